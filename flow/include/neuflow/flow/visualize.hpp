#pragma once
// Rendering a flow field with the standard colour wheel (see colorwheel.hpp).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

// An 8-bit RGB image, rows top to bottom, pixels interleaved R, G, B.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // 3 * width * height
};

struct VisualizeOptions {
  // The magnitude (px) that maps to full saturation. Fixed values keep colours comparable
  // across frames; nullopt normalizes each image by its largest valid magnitude.
  std::optional<double> max_flow;
};

struct Visualization {
  RgbImage image;
  double max_flow = 0;  // the magnitude that was used for full saturation
};

// The largest |(u, v)| over valid pixels with finite values; 0 if there is none.
double max_flow_magnitude(const FlowField& field);

// Invalid pixels (mask 0 or non-finite values) are black. With per-image normalization a
// field without motion (max 0) renders white. Throws std::invalid_argument for an
// inconsistent field or a max_flow that is not positive and finite.
Visualization visualize_flow(const FlowField& field, const VisualizeOptions& options = {});

// Writes an RGB image as an 8-bit PNG, atomically. Throws FlowFileError (write_failed), or
// std::invalid_argument for an inconsistent image.
void write_rgb_png(const RgbImage& image, const std::filesystem::path& path);

}  // namespace neuflow::flow
