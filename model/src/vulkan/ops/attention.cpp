#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// out[:, i] = Σ_j softmax_j(q[:, i] · k[:, j]) v[:, j] in one dispatch (flash_attention.comp):
// the score matrix is never written.
void record_op(Recorder& r, const graph::Attention& op) {
  const View q = r.view(op.q), k = r.view(op.k), v = r.view(op.v), out = r.view(op.out);
  r.flash_attention(q, k, v, out, 1.f, false, op.across_frames);
}

}  // namespace neuflow::model::vulkan
