#include "common/png_name.hpp"

#include <cctype>

namespace neuflow::cli {

std::string png_name(const std::string& name) {
  std::string ext = name.size() >= 4 ? name.substr(name.size() - 4) : std::string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png" ? std::string() : "the picture is written as PNG; give it a .png name";
}

}  // namespace neuflow::cli
