#include <algorithm>
#include <cmath>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// softmax(f0ᵀ f1 / √c) in blocks of rows, each block's correspondences = grid · blockᵀ; then
// flow = correspondence - grid.
void record_op(Recorder& r, const graph::GlobalMatching& op) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), grid = r.view(op.grid), out = r.view(op.out);
  const View scores = r.view({op.scores, 0, 1}), correspondence = r.view({op.correspondence, 0, 2});
  const int l = f0.h * f0.w;
  const float alpha = 1.f / std::sqrt(static_cast<float>(f0.c));
  for (int r0 = 0; r0 < l; r0 += op.block_rows) {
    const int n = std::min(op.block_rows, l - r0);
    r.matmul(*f0.buffer, *f1.buffer, *scores.buffer,
             {n, l, f0.c, f0.offset() + r0, 1, l, f1.offset(), l, 1, scores.offset(), l, 1, -1, kActNone, alpha});
    const long long block = static_cast<long long>(n) * l;
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, scores.buffer, nullptr},
                                     SoftmaxRowsParams{n, l, scores.offset()}, {r.bytes(block), r.bytes(block), 0},
                                     static_cast<uint32_t>(n));
    r.matmul(
        *grid.buffer, *scores.buffer, *correspondence.buffer,
        {2, n, l, grid.offset(), l, 1, scores.offset(), 1, l, correspondence.offset() + r0, l, 1, -1, kActNone, 1.f});
  }
  const AxpbyParams p{out.count(), correspondence.offset(), grid.offset(), out.offset(), 1.f, -1.f};
  r.dispatch<Shader::axpby>({correspondence.buffer, grid.buffer, out.buffer, nullptr}, p,
                            {r.bytes(2LL * out.count()), r.bytes(out.count()), 0}, groups(out.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
