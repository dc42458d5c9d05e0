#include "convert/index.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

#include "common/exit_codes.hpp"
#include "convert/input_error.hpp"

namespace neuflow::cli {

namespace {

// Temporary file beside the target, flushed to disk, renamed over it: the same guarantee
// the flow library gives the flow files.
void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  const auto temp = path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()));
  int fd = -1;
  const auto fail = [&](const std::string& what) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    ::unlink(temp.c_str());
    throw InputError(kExitCantCreate, path.string() + ": " + what + ": " + std::generic_category().message(err));
  };
  fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail("cannot create the index");
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("cannot write the index");
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("cannot flush the index to disk");
  const int closing = fd;
  fd = -1;
  if (::close(closing) != 0) fail("cannot write the index");
  if (::rename(temp.c_str(), path.c_str()) != 0) fail("cannot replace the index");
}

}  // namespace

void FlowIndex::write() const {
  std::string text = flow::flow_index_header();
  for (const auto& r : rows_) text += flow::flow_index_row(r);
  write_text_atomically(path_, text);
}

}  // namespace neuflow::cli
