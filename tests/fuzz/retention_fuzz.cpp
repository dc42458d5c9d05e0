// neuflowsink's retention matching (plugins/src/earlier_files.hpp): the input's first line is a
// location pattern, each further line a file name created in the pattern's folder. Every file
// retention counts must be one the sink could have written: the name the pattern gives for its
// index, exactly (other tools' files in the folder are never the sink's to delete).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "earlier_files.hpp"
#include "fuzz_support.hpp"

namespace fs = std::filesystem;

namespace {

// A name the folder can hold and that stays inside it.
bool usable(const std::string& name) {
  return !name.empty() && name.size() < 128 && name != "." && name != ".." &&
         name.find_first_of(std::string("/\0", 2)) == std::string::npos;
}

// The sink refuses patterns other than one integer conversion (and %%); so does this harness.
bool one_integer_conversion(const std::string& pattern) {
  static const std::regex one("([^%]|%%)*%0?[1-9]?d([^%]|%%)*");
  return std::regex_match(pattern, one);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const fs::path dir = fs::temp_directory_path() / ("neuflow-fuzz-retention-" + std::to_string(::getpid()));
  std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
  std::string pattern;
  if (!std::getline(lines, pattern) || !usable(pattern) || !one_integer_conversion(pattern)) return 0;
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  int files = 0;
  for (std::string name; files < 32 && std::getline(lines, name);) {
    if (!usable(name)) continue;
    std::ofstream(dir / name) << name;
    ++files;
  }
  try {
    const std::string location = (dir / pattern).string();
    for (const auto& file : neuflow::gst::files_matching(location)) {
      const std::string name = fs::path(file.path).filename().string();
      if (file.index < 0 || file.index > std::numeric_limits<int>::max() ||
          neuflow::gst::format_index_name(pattern, static_cast<int>(file.index)) != name) {
        neuflow::fuzz::invariant_failed("retention", "'" + name + "' counted as index " + std::to_string(file.index) +
                                                         " of '" + pattern + "', which names that index otherwise");
      }
    }
  } catch (...) {
    neuflow::fuzz::unexpected_exception("retention");
  }
  return 0;
}
