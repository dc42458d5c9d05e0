#pragma once
// An image file's dimensions from its header, before anything is decoded: so that a small file
// that would decode to gigabytes (a 20000×20000 PNG is 1.2 MB) is refused by its size, not after
// the allocation. PNG (libpng) and JPEG (libjpeg) are read; other formats are left to OpenCV's
// decoder and its own pixel cap.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace neuflow::cli {

struct ImageDimensions {
  int width = 0, height = 0;
};

// The dimensions a PNG or JPEG header states; nothing for another format, or for a header the
// library cannot read (the decoder then reports what is wrong with the file).
std::optional<ImageDimensions> image_dimensions(const std::filesystem::path& path);

// Why frames of a size cannot be taken (FlowSession::frame_problem), or nothing.
using FrameSizeCheck = std::function<std::optional<std::string>(int width, int height)>;

// "<path>: its header says WxH: <problem>" where the header's size fails `check`, else nothing.
std::optional<std::string> image_too_large(const std::filesystem::path& path, const FrameSizeCheck& check);

}  // namespace neuflow::cli
