#include "support/temp_dir.hpp"

#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cerrno>
#include <stdexcept>
#include <system_error>

namespace neuflow::test {

namespace fs = std::filesystem;

namespace {

// Adds owner read/write/search to `dir` and to every folder below it (never through a
// symbolic link: links may point at fixtures outside the folder), so remove_all can empty it.
void restore_owner_access(const fs::path& dir) {
  std::error_code ec;
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add, ec);
  // Each folder is made accessible when the iterator reaches it, before it descends.
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_directory(type_ec) && !it->is_symlink(type_ec)) {
      std::error_code perm_ec;
      fs::permissions(it->path(), fs::perms::owner_all, fs::perm_options::add, perm_ec);
    }
  }
}

}  // namespace

TempDir::TempDir(std::string_view prefix) {
  std::error_code ec;
  const fs::path base = fs::temp_directory_path(ec);
  if (ec) throw std::runtime_error("cannot find the temporary folder: " + ec.message());
  std::string pattern = (base / (std::string(prefix) + "-XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    const int err = errno;
    throw std::runtime_error("cannot create a temporary folder " + pattern + ": " +
                             std::generic_category().message(err));
  }
  path_ = pattern;
}

TempDir::~TempDir() {
  restore_owner_access(path_);
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::vector<std::string> TempDir::entries() const {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace neuflow::test
