#pragma once
// Limits every reader checks a file's header against before it allocates anything, so a
// corrupt or hostile header cannot ask for gigabytes. They are far above any real flow
// benchmark (the largest, Spring, is 3840×2160 ≈ 2^23 pixels).
#include <cstdint>

namespace neuflow::flow {

inline constexpr std::int64_t kMaxFlowSide = 32768;
inline constexpr std::int64_t kMaxFlowPixels = std::int64_t{1} << 28;

// True when width × height is a field size the readers and writers accept.
constexpr bool flow_size_acceptable(std::int64_t width, std::int64_t height) {
  return width > 0 && height > 0 && width <= kMaxFlowSide && height <= kMaxFlowSide && width * height <= kMaxFlowPixels;
}

}  // namespace neuflow::flow
