#pragma once
// A dense optical-flow field: per pixel the displacement (u right, v down) in pixels from
// frame 0 to frame 1, with an optional validity mask for sparse ground truth.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace neuflow::flow {

struct FlowField {
  int width = 0;
  int height = 0;
  std::vector<float> uv;       // interleaved u,v; row-major; size 2 * width * height
  std::vector<uint8_t> valid;  // empty: every pixel valid; else width * height, 0 = invalid

  FlowField() = default;
  FlowField(int w, int h) : width(w), height(h), uv(2 * static_cast<std::size_t>(w) * h, 0.f) {}

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
  bool has_mask() const { return !valid.empty(); }
  bool is_valid(int x, int y) const { return valid.empty() || valid[index(x, y)] != 0; }
  float& u(int x, int y) { return uv[2 * index(x, y)]; }
  float& v(int x, int y) { return uv[2 * index(x, y) + 1]; }
  float u(int x, int y) const { return uv[2 * index(x, y)]; }
  float v(int x, int y) const { return uv[2 * index(x, y) + 1]; }

 private:
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * width + x; }
};

}  // namespace neuflow::flow
