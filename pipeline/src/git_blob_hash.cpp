#include "neuflow/pipeline/git_blob_hash.hpp"

#include <openssl/evp.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace neuflow::pipeline {

void GitBlobHasher::FreeContext::operator()(evp_md_ctx_st* ctx) const { EVP_MD_CTX_free(ctx); }

GitBlobHasher::GitBlobHasher(std::uint64_t size) : ctx_(EVP_MD_CTX_new()), size_(size) {
  if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha1(), nullptr) != 1) {
    throw std::runtime_error("OpenSSL cannot provide SHA-1 (is the default provider disabled?)");
  }
  const std::string header = "blob " + std::to_string(size) + '\0';
  EVP_DigestUpdate(ctx_.get(), header.data(), header.size());
}

GitBlobHasher::~GitBlobHasher() = default;

void GitBlobHasher::update(std::span<const std::byte> bytes) {
  if (bytes.empty()) return;
  EVP_DigestUpdate(ctx_.get(), bytes.data(), bytes.size());
  fed_ += bytes.size();
}

std::string GitBlobHasher::hex_digest() {
  if (fed_ != size_) {
    throw std::logic_error("git blob hash of " + std::to_string(size_) + " bytes fed " + std::to_string(fed_));
  }
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx_.get(), digest.data(), &length);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0xf];
  }
  return hex;
}

std::string git_blob_sha1_of_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw std::runtime_error(path.string() + ": " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open: " + std::strerror(errno));
  GitBlobHasher hasher(size);
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    hasher.update(std::as_bytes(std::span(buffer.data(), got)));
  }
  if (in.bad() || hasher.fed() != size) {
    throw std::runtime_error(path.string() + ": read error (or the file changed while it was hashed)");
  }
  return hasher.hex_digest();
}

bool is_sha1_hex(std::string_view text) {
  if (text.size() != 40) return false;
  for (const char c : text) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

}  // namespace neuflow::pipeline
