#include "graph/tensors.hpp"
#include "network_dims.hpp"

namespace neuflow::model::graph {

std::vector<float> constant_values(const TensorDesc& t) {
  if (!t.constant) return {};
  const std::size_t plane = t.plane();
  std::vector<float> v(plane * static_cast<std::size_t>(t.constant->count));
  const auto at = [&](int channel, int y, int x) -> float& {
    return v[static_cast<std::size_t>(channel) * plane + static_cast<std::size_t>(y) * t.w + x];
  };
  for (int y = 0; y < t.h; ++y) {
    for (int x = 0; x < t.w; ++x) {
      switch (t.constant->fill) {
        case Fill::position_yx:
          at(0, y, x) = static_cast<float>(y) - static_cast<float>(t.h) / 2.f;
          at(1, y, x) = static_cast<float>(x) - static_cast<float>(t.w) / 2.f;
          break;
        case Fill::grid_xy:
          at(0, y, x) = static_cast<float>(x);
          at(1, y, x) = static_cast<float>(y);
          break;
        case Fill::radius_plane:
          for (int c = 0; c < t.constant->count; ++c) at(c, y, x) = kCorrRadiusPlane;
          break;
      }
    }
  }
  return v;
}

}  // namespace neuflow::model::graph
