#include "fetch_model/fetch.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "fetch_model/error.hpp"
#include "fetch_model/hash.hpp"

namespace neuflow::cli {

namespace fs = std::filesystem;
using Kind = FetchError::Kind;

namespace {

// The checkpoints in the root of github.com/neufieldrobotics/NeuFlow_v2, each pinned by its
// git blob SHA-1 (what `git ls-tree` in a clone of that repository lists for the file).
constexpr std::array<PublishedModel, 3> kPublished{{
    {"mixed", "neuflow_mixed.pth", "2152e111910de87297af42923d6ed679958b713d"},
    {"sintel", "neuflow_sintel.pth", "36a2f3a2a7d9896237655c459fc845096100c92e"},
    {"things", "neuflow_things.pth", "a1cff3c49d80fc1dde3c655119c0e23898a1b0f6"},
}};

// A published checkpoint is about 36 MB. Refusing far larger bodies keeps a wrong URL (an
// ISO image on a mirror, an endless stream) from filling the disk before the hash can say no.
constexpr std::uint64_t kMaxBytes = std::uint64_t{1} << 30;

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

// The download lands here first, in the destination's directory so the final rename is
// atomic. Unless commit() succeeds, the destructor removes it.
class TempFile {
 public:
  explicit TempFile(const fs::path& destination) {
    const fs::path dir = destination.has_parent_path() ? destination.parent_path() : fs::path(".");
    std::string pattern = (dir / ("." + destination.filename().string() + ".part-XXXXXX")).string();
    fd_ = ::mkstemp(pattern.data());
    if (fd_ < 0) {
      throw FetchError(Kind::kLocalIo,
                       "cannot create a temporary file in " + dir.string() + ": " + std::strerror(errno));
    }
    path_ = pattern;
    // mkstemp creates the file 0600; the checkpoint gets what any new file would.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd_, 0666 & ~mask);
  }
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(path_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  const fs::path& path() const { return path_; }

  void write(std::span<const std::byte> bytes) {
    const auto* data = reinterpret_cast<const char*>(bytes.data());
    std::size_t left = bytes.size();
    while (left > 0) {
      const ssize_t n = ::write(fd_, data, left);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) fail("writing");
      data += n;
      left -= static_cast<std::size_t>(n);
    }
  }

  // Durable before visible: the data reaches the disk before the name points at it, so a
  // power cut cannot leave a destination that exists but holds garbage.
  void commit(const fs::path& destination) {
    if (::fsync(fd_) != 0) fail("flushing");
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail("closing");
    if (::rename(path_.c_str(), destination.c_str()) != 0) {
      throw FetchError(Kind::kLocalIo,
                       "cannot rename " + path_.string() + " to " + destination.string() + ": " + std::strerror(errno));
    }
    committed_ = true;
    const fs::path dir = destination.has_parent_path() ? destination.parent_path() : fs::path(".");
    // Best effort: some file systems refuse fsync on directories, and the file itself is safe.
    if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY); dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  }

 private:
  [[noreturn]] void fail(const char* doing) const {
    const int e = errno;
    std::string message = std::string(doing) + " " + path_.string() + " failed: " + std::strerror(e);
    if (e == ENOSPC || e == EDQUOT || e == EFBIG) message += " (free some space or pick another --output-dir)";
    throw FetchError(Kind::kLocalIo, message);
  }

  fs::path path_;
  int fd_ = -1;
  bool committed_ = false;
};

// Creates the destination's missing folders; unless keep() is called, the destructor removes
// the ones it created (when they are still empty), so a failed download leaves nothing behind.
class CreatedDirectories {
 public:
  explicit CreatedDirectories(const fs::path& dir) {
    if (dir.empty()) return;
    std::error_code ec;
    for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
      created_.push_back(p);
      if (p == p.parent_path()) break;
    }
    fs::create_directories(dir, ec);
    if (ec) {
      remove_created();
      throw FetchError(Kind::kLocalIo, "cannot create the directory " + dir.string() + ": " + ec.message());
    }
  }
  ~CreatedDirectories() {
    if (!kept_) remove_created();
  }
  CreatedDirectories(const CreatedDirectories&) = delete;
  CreatedDirectories& operator=(const CreatedDirectories&) = delete;

  void keep() { kept_ = true; }

 private:
  void remove_created() {
    std::error_code ec;
    for (const auto& p : created_) fs::remove(p, ec);  // deepest first; only empty folders go
  }

  std::vector<fs::path> created_;  // deepest first
  bool kept_ = false;
};

// Writes the body to the temporary file and hashes it on the way, so the file is never
// read back — except when the server sends no Content-Length, which the git hash needs first.
class VerifyingSink : public HttpBodySink {
 public:
  VerifyingSink(TempFile& file, const std::string& url) : file_(file), url_(url) {}

  void begin(std::int64_t content_length) override {
    if (content_length >= 0 && static_cast<std::uint64_t>(content_length) > kMaxBytes) too_large(content_length);
    if (content_length >= 0) hasher_.emplace(static_cast<std::uint64_t>(content_length));
  }

  void write(std::span<const std::byte> chunk) override {
    received_ += chunk.size();
    if (received_ > kMaxBytes) too_large(-1);
    file_.write(chunk);
    if (hasher_) hasher_->update(chunk);
  }

  std::uint64_t received() const { return received_; }

  std::string sha1() {
    if (!hasher_) return git_blob_sha1_of_file(file_.path());
    if (hasher_->fed() != hasher_->size()) {
      throw FetchError(Kind::kUnavailable, url_ + ": received " + std::to_string(hasher_->fed()) +
                                               " bytes but the server announced " + std::to_string(hasher_->size()) +
                                               "; try again");
    }
    return hasher_->hex_digest();
  }

 private:
  [[noreturn]] void too_large(std::int64_t announced) const {
    const std::string size = announced >= 0 ? std::to_string(announced) + " bytes" : "more than that";
    throw FetchError(Kind::kIntegrity, url_ + ": the server sends " + size +
                                           ", but a checkpoint is far smaller (limit " + std::to_string(kMaxBytes) +
                                           " bytes); is the URL right?");
  }

  TempFile& file_;
  const std::string& url_;
  std::optional<GitBlobHasher> hasher_;
  std::uint64_t received_ = 0;
};

// True when the destination already holds the expected file; throws when it holds
// something else that must not be silently replaced.
bool already_present(const FetchRequest& request, const std::string& expected) {
  std::error_code ec;
  const auto status = fs::status(request.destination, ec);
  if (ec || !fs::exists(status)) return false;
  if (!fs::is_regular_file(status)) {
    throw FetchError(Kind::kLocalIo, request.destination.string() + " exists and is not a regular file");
  }
  if (request.force) return false;
  const std::string actual = git_blob_sha1_of_file(request.destination);
  if (actual == expected) return true;
  throw FetchError(Kind::kLocalIo, request.destination.string() +
                                       " already exists but is not the expected file (git blob SHA-1 " + actual +
                                       ", expected " + expected + "); pass --force to replace it");
}

}  // namespace

std::span<const PublishedModel> published_models() { return kPublished; }

const PublishedModel* find_published_model(std::string_view name) {
  for (const auto& model : kPublished) {
    if (model.name == name) return &model;
  }
  return nullptr;
}

std::string model_url(std::string_view base_url, std::string_view file) {
  while (!base_url.empty() && base_url.back() == '/') base_url.remove_suffix(1);
  return std::string(base_url) + "/" + std::string(file);
}

FetchResult fetch_model(const FetchRequest& request) {
  if (!is_sha1_hex(request.expected_sha1)) {
    throw FetchError(Kind::kIntegrity, "'" + request.expected_sha1 + "' is not a SHA-1 (40 hex digits)");
  }
  const std::string expected = lowercase(request.expected_sha1);
  if (already_present(request, expected)) return {false, fs::file_size(request.destination), expected};

  CreatedDirectories created(request.destination.has_parent_path() ? request.destination.parent_path() : fs::path());

  TempFile file(request.destination);
  VerifyingSink sink(file, request.url);
  http_get(request.url, sink, request.http);
  const std::string actual = sink.sha1();
  if (actual != expected) {
    throw FetchError(Kind::kIntegrity, request.url + " is not the pinned file (its git blob SHA-1 is " + actual +
                                           ", expected " + expected + "), so nothing was saved; if you trust this " +
                                           "file, rerun with --sha1 " + actual);
  }
  if (request.accept) request.accept(file.path());
  file.commit(request.destination);
  created.keep();
  return {true, sink.received(), expected};
}

}  // namespace neuflow::cli
