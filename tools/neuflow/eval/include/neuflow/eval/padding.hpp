#pragma once
// The padding of the reference evaluation (RAFT's InputPadder, reused by NeuFlow-V2 with a
// factor of 16): edge replication up to the next multiple, split evenly left/right, and
// either split evenly top/bottom ("sintel" mode) or all at the bottom ("kitti" mode). Where
// a split is odd the extra pixel goes right / bottom (pad // 2 before, the rest after).
#include <opencv2/core.hpp>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::eval {

enum class PadMode {
  centred,  // InputPadder mode "sintel": [pw/2, pw - pw/2, ph/2, ph - ph/2]
  bottom,   // InputPadder mode "kitti":  [pw/2, pw - pw/2, 0, ph]
};

struct Padding {
  int left = 0, right = 0, top = 0, bottom = 0;
  bool operator==(const Padding&) const = default;
};

// The padding that brings width × height up to multiples of `multiple`. Throws
// std::invalid_argument for a non-positive size or multiple.
Padding reference_padding(int width, int height, PadMode mode, int multiple = 16);

// The image with its border replicated by `padding` (any OpenCV type).
cv::Mat pad_image(const cv::Mat& image, const Padding& padding);

// The inverse for the flow computed on a padded image: the window that held the original
// pixels (vectors unchanged, the mask cropped along). Throws std::invalid_argument when the
// field is not larger than the padding.
flow::FlowField crop_flow(const flow::FlowField& padded, const Padding& padding);

}  // namespace neuflow::eval
