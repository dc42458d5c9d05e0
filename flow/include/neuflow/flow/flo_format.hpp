#pragma once
// Middlebury .flo: the bytes "PIEH" (float 202021.25 little-endian), int32 width, int32
// height, then float32 u,v interleaved row by row, all little-endian. The format has no mask;
// it marks unknown flow with huge values instead (the Middlebury convention: |u| or |v| > 1e9).
//
// Reading: a pixel whose u or v is unknown (> 1e9 in magnitude), infinite or NaN becomes
// invalid in the mask and gets u = v = 0 as a finite placeholder, so code that ignores the
// mask never meets 1e10 or NaN. The mask is left empty when every pixel is known.
//
// Writing: a pixel that is invalid in the mask, or whose u or v is not finite, is written as
// u = v = 1e10 (unknown), so masks survive a round trip. A valid value beyond ±1e9 is
// written as it is and will read back as unknown; no real flow is that large.
#include <filesystem>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

inline constexpr float kFloMagic = 202021.25f;
inline constexpr float kFloUnknownThreshold = 1e9f;  // larger magnitudes mean "unknown"
inline constexpr float kFloUnknownValue = 1e10f;     // what we write for invalid pixels

// Throws FlowFileError.
FlowField read_flo(const std::filesystem::path& path);
// Atomic: the file appears complete or not at all. Throws FlowFileError, or
// std::invalid_argument if the field is inconsistent (sizes of uv / valid).
void write_flo(const FlowField& field, const std::filesystem::path& path);

}  // namespace neuflow::flow
