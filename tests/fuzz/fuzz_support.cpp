#include "fuzz_support.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <typeinfo>

#include <cxxabi.h>

namespace neuflow::fuzz {

namespace {

[[noreturn]] void die(const char* what) {
  std::fprintf(stderr, "fuzz harness setup: %s: %s\n", what, std::strerror(errno));
  std::abort();
}

std::string demangled(const char* name) {
  int status = 0;
  char* text = abi::__cxa_demangle(name, nullptr, nullptr, &status);
  std::string out = status == 0 && text != nullptr ? text : name;
  std::free(text);
  return out;
}

}  // namespace

InputFile::InputFile(const char* name) {
  fd_ = ::memfd_create(name, MFD_CLOEXEC);
  if (fd_ < 0) die("memfd_create");
  path_ = "/proc/self/fd/" + std::to_string(fd_);
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

const std::filesystem::path& InputFile::write(const std::uint8_t* data, std::size_t size) {
  if (::ftruncate(fd_, 0) != 0) die("ftruncate");
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(fd_, data + done, size - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) die("pwrite");
    done += static_cast<std::size_t>(n);
  }
  return path_;
}

void unexpected_exception(const char* harness) noexcept {
  std::string type = "an exception of unknown type";
  std::string message;
  try {
    const std::exception_ptr current = std::current_exception();
    if (current) std::rethrow_exception(current);
    type = "no exception (unexpected_exception called outside a catch block)";
  } catch (const std::exception& e) {
    type = demangled(typeid(e).name());
    message = e.what();
  } catch (...) {
    if (const std::type_info* info = abi::__cxa_current_exception_type()) type = demangled(info->name());
  }
  std::fprintf(stderr, "\n==FUZZ== %s: undocumented exception %s: %s\n", harness, type.c_str(), message.c_str());
  std::abort();
}

void invariant_failed(const char* harness, const std::string& what) noexcept {
  std::fprintf(stderr, "\n==FUZZ== %s: broken invariant of a successful result: %s\n", harness, what.c_str());
  std::abort();
}

}  // namespace neuflow::fuzz
