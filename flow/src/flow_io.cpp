#include "neuflow/flow/flow_io.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flo_format.hpp"
#include "neuflow/flow/kitti_png_format.hpp"
#include "neuflow/flow/npy_format.hpp"

namespace neuflow::flow {

namespace {

FlowFormat require_format(const std::filesystem::path& path) {
  if (auto format = flow_format_from_path(path)) return *format;
  const std::string ext = path.extension().string();
  throw FlowFileError(FlowFileError::Kind::unsupported_format, path,
                      (ext.empty() ? std::string("no file extension") : "unknown flow file extension '" + ext + "'") +
                          " (expected .flo, .png or .npy)");
}

}  // namespace

std::optional<FlowFormat> flow_format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".flo") return FlowFormat::flo;
  if (ext == ".png") return FlowFormat::kitti_png;
  if (ext == ".npy") return FlowFormat::npy;
  return std::nullopt;
}

std::string_view to_string(FlowFormat format) {
  switch (format) {
    case FlowFormat::flo: return "Middlebury .flo";
    case FlowFormat::kitti_png: return "KITTI 16-bit PNG";
    case FlowFormat::npy: return "NumPy .npy";
  }
  return "unknown";
}

FlowField read_flow(const std::filesystem::path& path) {
  // A missing file is the more useful complaint when both apply (e.g. a typo in the name).
  std::error_code ec;
  if (!flow_format_from_path(path) && !std::filesystem::exists(path, ec)) {
    throw FlowFileError(FlowFileError::Kind::not_found, path, "no such file");
  }
  switch (require_format(path)) {
    case FlowFormat::flo: return read_flo(path);
    case FlowFormat::kitti_png: return read_kitti_png(path);
    case FlowFormat::npy: return read_npy(path);
  }
  return {};  // unreachable: every enumerator is handled above
}

void write_flow(const FlowField& field, const std::filesystem::path& path) {
  switch (require_format(path)) {
    case FlowFormat::flo: write_flo(field, path); return;
    case FlowFormat::kitti_png: write_kitti_png(field, path); return;
    case FlowFormat::npy: write_npy(field, path); return;
  }
}

}  // namespace neuflow::flow
