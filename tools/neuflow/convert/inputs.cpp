#include "convert/inputs.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <set>
#include <string_view>

#include "common/exit_codes.hpp"

namespace neuflow::cli {

namespace fs = std::filesystem;

namespace {

bool is_uri(const std::string& s) {
  const auto scheme_end = s.find("://");
  return scheme_end != std::string::npos && scheme_end > 0 &&
         std::all_of(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(scheme_end),
                     [](unsigned char c) { return std::isalnum(c) || c == '+' || c == '-' || c == '.'; });
}

// The name a path is known by: "frames/" and "frames" are both "frames", "." is the
// current folder's name.
std::string base_name(const std::string& path, bool keep_extension) {
  fs::path p(path);
  if (p.filename().empty() || p.filename() == "." || p.filename() == "..") {
    std::error_code ec;
    p = fs::weakly_canonical(fs::absolute(p, ec), ec);
  }
  const auto name = keep_extension ? p.filename() : p.stem();
  return name.empty() ? std::string() : name.string();
}

// The last path segment without extension, or the host's first label when there is no path
// (rtsp://camera.local/ -> camera).
std::string uri_name(const std::string& uri) {
  std::string_view rest(uri);
  rest = rest.substr(0, rest.find_first_of("?#"));
  while (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
  const auto slash = rest.find_last_of('/');
  const auto host_end = uri.find("://") + 3;
  if (slash == std::string_view::npos || slash + 1 < host_end) return std::string();
  return fs::path(std::string(rest.substr(slash + 1))).stem().string();
}

// Keeps names usable as one folder name: no separators, not hidden, never empty.
std::string clean_name(std::string name) {
  for (char& c : name) {
    if (c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20) c = '_';
  }
  while (!name.empty() && name.front() == '.') name.erase(name.begin());
  return name.empty() ? std::string("input") : name;
}

InputSpec image_pair(const std::string& a, const std::string& b) {
  InputSpec spec;
  spec.kind = InputKind::image_pair;
  spec.paths = {a, b};
  spec.label = a + " + " + b;
  spec.output_name = clean_name(fs::path(a).stem().string() + "_" + fs::path(b).stem().string());
  return spec;
}

InputSpec single(const std::string& path, bool lone_image) {
  InputSpec spec;
  spec.paths = {path};
  spec.label = path;
  if (is_uri(path)) {
    spec.kind = InputKind::video;
    spec.output_name = clean_name(uri_name(path));
    return spec;
  }
  std::error_code ec;
  const auto status = fs::status(path, ec);
  spec.kind = fs::is_directory(status) ? InputKind::image_folder : InputKind::video;
  spec.output_name = clean_name(base_name(path, false));
  if (!fs::exists(status)) {
    spec.rejected = InputError(kExitNoInput, "no such file or folder");
  } else if (lone_image) {
    spec.rejected =
        InputError(kExitFailure, "a single image has no pair: give two images (or --pair A B), or a folder of frames");
  }
  return spec;
}

}  // namespace

bool has_image_extension(const std::string& path) {
  static constexpr std::array<std::string_view, 11> kExtensions = {".png",  ".jpg", ".jpeg", ".bmp", ".tif", ".tiff",
                                                                   ".webp", ".ppm", ".pgm",  ".pnm", ".jpe"};
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return std::find(kExtensions.begin(), kExtensions.end(), ext) != kExtensions.end();
}

std::vector<InputSpec> plan_inputs(const std::vector<std::string>& positional,
                                   const std::vector<std::pair<std::string, std::string>>& pairs) {
  std::vector<InputSpec> specs;
  for (const auto& [a, b] : pairs) specs.push_back(image_pair(a, b));

  const auto is_image = [](const std::string& p) {
    return !is_uri(p) && !fs::is_directory(p) && has_image_extension(p);
  };
  const auto images = std::count_if(positional.begin(), positional.end(), is_image);
  bool pair_added = false;
  for (const auto& path : positional) {
    if (!is_image(path)) {
      specs.push_back(single(path, false));
    } else if (images == 2 && !pair_added) {
      const auto second =
          std::find_if(std::find(positional.begin(), positional.end(), path) + 1, positional.end(), is_image);
      specs.push_back(image_pair(path, *second));
      pair_added = true;
    } else if (images != 2) {
      specs.push_back(single(path, true));
    }
  }

  // Stable names: the first input keeps its name, later ones with the same name get a suffix.
  std::set<std::string> taken;
  for (auto& spec : specs) {
    std::string name = spec.output_name;
    for (int n = 2; taken.count(name) != 0; ++n) name = spec.output_name + "_" + std::to_string(n);
    spec.output_name = name;
    taken.insert(name);
  }
  return specs;
}

}  // namespace neuflow::cli
