#include "file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <random>
#include <system_error>

#include "neuflow/flow/errors.hpp"

namespace neuflow::flow::detail {

namespace {

using Kind = FlowFileError::Kind;

std::string errno_text(int err) { return std::generic_category().message(err); }

// A name unlikely to collide with a concurrent writer of the same target, in the same
// directory so that rename() stays within one file system and is atomic.
std::filesystem::path temporary_sibling(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  static const unsigned seed = std::random_device{}();
  const unsigned tag = seed ^ (counter.fetch_add(1) * 2654435761u) ^ static_cast<unsigned>(::getpid());
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, ".tmp-%08x", tag);
  auto name = "." + path.filename().string() + suffix;
  return path.parent_path() / name;
}

}  // namespace

BinaryInput::BinaryInput(const std::filesystem::path& path) : path_(path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw FlowFileError(Kind::not_found, path, "no such file");
  if (std::filesystem::is_directory(status)) {
    throw FlowFileError(Kind::not_found, path, "is a directory, not a file");
  }
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) throw FlowFileError(Kind::not_found, path, "cannot open: " + errno_text(errno));
  struct stat st {};
  if (::fstat(::fileno(file_.get()), &st) != 0) {
    throw FlowFileError(Kind::not_found, path, "cannot stat: " + errno_text(errno));
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

void BinaryInput::read(std::span<std::byte> out, const char* what) {
  const std::size_t got = std::fread(out.data(), 1, out.size(), file_.get());
  if (got != out.size()) {
    if (std::ferror(file_.get()) != 0) {
      throw FlowFileError(Kind::not_found, path_, std::string("read error in ") + what);
    }
    throw FlowFileError(Kind::malformed, path_,
                        "truncated: the " + std::string(what) + " needs " + std::to_string(out.size()) +
                            " bytes at offset " + std::to_string(position_) + " but the file is only " +
                            std::to_string(size_) + " bytes");
  }
  position_ += got;
}

std::vector<std::byte> read_whole_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
  BinaryInput in(path);
  if (in.size() > max_bytes) {
    throw FlowFileError(Kind::malformed, path,
                        "file is " + std::to_string(in.size()) + " bytes, more than the " + std::to_string(max_bytes) +
                            " bytes accepted");
  }
  std::vector<std::byte> bytes(static_cast<std::size_t>(in.size()));
  in.read(bytes, "file contents");
  return bytes;
}

void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  if (path.filename().empty()) throw FlowFileError(Kind::write_failed, path, "no file name given");

  std::filesystem::path temp;
  int fd = -1;
  for (int attempt = 0; attempt < 16 && fd < 0; ++attempt) {
    temp = temporary_sibling(path);
    // 0666 lets the umask decide the final permissions, as for any newly created file.
    fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) {
      throw FlowFileError(Kind::write_failed, path,
                          "cannot create a file in " +
                              (path.parent_path().empty() ? std::string(".") : path.parent_path().string()) + ": " +
                              errno_text(errno));
    }
  }
  if (fd < 0) throw FlowFileError(Kind::write_failed, path, "cannot create a temporary file");

  auto fail = [&](const std::string& what, int err) {
    if (fd >= 0) ::close(fd);
    ::unlink(temp.c_str());
    throw FlowFileError(Kind::write_failed, path, what + ": " + errno_text(err));
  };

  const auto* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  // Without fsync a power loss after rename() can leave an empty file under the final name.
  if (::fsync(fd) != 0) fail("fsync failed", errno);
  const int fd_to_close = fd;
  fd = -1;
  if (::close(fd_to_close) != 0) fail("close failed", errno);
  if (::rename(temp.c_str(), path.c_str()) != 0) fail("cannot replace the file", errno);
  // Makes the rename itself durable. Best effort: the file is complete either way, and some
  // file systems refuse fsync on directories.
  const auto dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  if (const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace neuflow::flow::detail
