#pragma once
// Reading and writing flow files by extension: .flo (Middlebury), .png (KITTI 16-bit),
// .npy (NumPy H×W×2 float32). The extension is matched case-insensitively. See each
// format's header for how it represents invalid pixels.
#include <filesystem>
#include <optional>
#include <string_view>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

enum class FlowFormat { flo, kitti_png, npy };

// The format named by path's extension, or nullopt if it names none.
std::optional<FlowFormat> flow_format_from_path(const std::filesystem::path& path);
std::string_view to_string(FlowFormat format);

// Throw FlowFileError (kind unsupported_format for an unknown extension).
FlowField read_flow(const std::filesystem::path& path);
void write_flow(const FlowField& field, const std::filesystem::path& path);

}  // namespace neuflow::flow
