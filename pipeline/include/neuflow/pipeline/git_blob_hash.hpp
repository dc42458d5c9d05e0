#pragma once
// Git blob SHA-1, the value `git hash-object FILE` prints and `git ls-tree` lists: SHA-1 over
// "blob <size>\0" followed by the content. The published checkpoints are pinned by it so that
// the pin can be checked against the official repository without downloading anything, and
// output folders record the model that made their flows by it (output_record.hpp).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

struct evp_md_ctx_st;  // OpenSSL's EVP_MD_CTX, kept out of this header

namespace neuflow::pipeline {

class GitBlobHasher {
 public:
  // Git hashes the length before the content, so the total must be known up front.
  explicit GitBlobHasher(std::uint64_t size);
  ~GitBlobHasher();
  GitBlobHasher(const GitBlobHasher&) = delete;
  GitBlobHasher& operator=(const GitBlobHasher&) = delete;

  void update(std::span<const std::byte> bytes);
  std::uint64_t size() const { return size_; }
  std::uint64_t fed() const { return fed_; }
  // The 40 lowercase hex digits. Throws std::logic_error unless exactly size() bytes were fed,
  // since anything else would not be git's hash of any file.
  std::string hex_digest();

 private:
  struct FreeContext {
    void operator()(evp_md_ctx_st* ctx) const;
  };
  std::unique_ptr<evp_md_ctx_st, FreeContext> ctx_;
  std::uint64_t size_;
  std::uint64_t fed_ = 0;
};

// The git blob SHA-1 of a file on disk. Throws std::runtime_error naming the file.
std::string git_blob_sha1_of_file(const std::filesystem::path& path);

// True for exactly 40 hex digits (either case).
bool is_sha1_hex(std::string_view text);

}  // namespace neuflow::pipeline
