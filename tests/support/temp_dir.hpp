#pragma once
// A unique, empty folder under the system's temporary folder for one test, removed with
// everything in it when the test is done.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace neuflow::test {

class TempDir {
 public:
  // Creates <temp>/<prefix>-XXXXXX (mkdtemp); throws std::runtime_error with the reason when
  // it cannot.
  explicit TempDir(std::string_view prefix = "neuflow-test");
  // Removes the folder and its contents, first giving the owner back full access to every
  // folder in it (tests make some read-only); errors are ignored.
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path_ / name; }

  // The names of everything directly in the folder, sorted: to check that nothing (a
  // temporary file, say) was left behind.
  std::vector<std::string> entries() const;

 private:
  std::filesystem::path path_;
};

}  // namespace neuflow::test
