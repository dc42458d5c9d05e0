#pragma once
// The one tensor type passed between stages: a single image's activations in NHWC order
// (channels fastest), which is what token lists, correlation and per-pixel ops want.
// Convolution chains keep oneDNN's blocked layouts internally and convert at their ends.
#include <cstddef>
#include <vector>

namespace neuflow::model {

struct Tensor {
  int h = 0;
  int w = 0;
  int c = 0;
  std::vector<float> data;

  Tensor() = default;
  Tensor(int height, int width, int channels)
      : h(height), w(width), c(channels), data(static_cast<std::size_t>(height) * width * channels, 0.f) {}

  void resize(int height, int width, int channels) {
    h = height;
    w = width;
    c = channels;
    data.assign(static_cast<std::size_t>(height) * width * channels, 0.f);
  }
  std::size_t pixels() const { return static_cast<std::size_t>(h) * w; }
  float* pixel(int y, int x) { return data.data() + (static_cast<std::size_t>(y) * w + x) * c; }
  const float* pixel(int y, int x) const { return data.data() + (static_cast<std::size_t>(y) * w + x) * c; }
};

}  // namespace neuflow::model
