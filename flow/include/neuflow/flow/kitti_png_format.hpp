#pragma once
// KITTI flow PNG: 16-bit RGB, u = (R − 2^15) / 64, v = (G − 2^15) / 64, valid where B > 0.
// OpenCV decodes it as BGR, so B is channel 0 of the decoded image and R is channel 2.
//
// Reading always yields a mask (the format is meant for sparse ground truth); invalid pixels
// get u = v = 0 as a finite placeholder, whatever their R and G were.
//
// Writing quantizes to 1/64 px, rounding to nearest (the KITTI devkit truncates; rounding
// halves the worst error and leaves multiples of 1/64 unchanged). Values outside the
// representable range [−512, +511.984375] are clamped to it. Invalid pixels (mask 0, or a
// non-finite u or v) are written as R = G = B = 0 like the devkit does; valid ones get B = 1.
#include <filesystem>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

inline constexpr float kKittiScale = 64.f;
inline constexpr float kKittiMinFlow = -32768.f / kKittiScale;  // -512
inline constexpr float kKittiMaxFlow = 32767.f / kKittiScale;   // 511.984375

// Throws FlowFileError: not a PNG, not 16-bit, not 3 channels, absurd size.
FlowField read_kitti_png(const std::filesystem::path& path);
// Atomic. Throws FlowFileError, or std::invalid_argument for an inconsistent field.
void write_kitti_png(const FlowField& field, const std::filesystem::path& path);

}  // namespace neuflow::flow
