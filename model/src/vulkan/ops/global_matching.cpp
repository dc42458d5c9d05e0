#include <cmath>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// flow = softmax(f0ᵀ f1 / √c) · gridᵀ - grid in one dispatch (flash_attention.comp with the
// grid as the values, less each token's own position): no score matrix, no correspondence.
void record_op(Recorder& r, const graph::GlobalMatching& op) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), grid = r.view(op.grid), out = r.view(op.out);
  r.flash_attention(f0, f1, grid, out, 1.f / std::sqrt(static_cast<float>(f0.c)), true);
}

}  // namespace neuflow::model::vulkan
