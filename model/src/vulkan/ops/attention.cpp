#include <algorithm>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// In blocks of rows: scores = qᵀ k, a softmax per row, message = v · scoresᵀ.
void record_op(Recorder& r, const graph::Attention& op) {
  const View q = r.view(op.q), k = r.view(op.k), v = r.view(op.v), out = r.view(op.out);
  const View scores = r.view({op.scores, 0, 1});
  const int l = q.h * q.w, dim = q.c;
  for (int r0 = 0; r0 < l; r0 += op.block_rows) {
    const int n = std::min(op.block_rows, l - r0);
    // scores[i][j] = q[:, r0 + i] · k[:, j]
    r.matmul(*q.buffer, *k.buffer, *scores.buffer,
             {n, l, dim, q.offset() + r0, 1, l, k.offset(), l, 1, scores.offset(), l, 1, -1, kActNone, 1.f});
    const long long block = static_cast<long long>(n) * l;
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, scores.buffer, nullptr},
                                     SoftmaxRowsParams{n, l, scores.offset()}, {r.bytes(block), r.bytes(block), 0},
                                     static_cast<uint32_t>(n));
    // message[:, r0 + i] = v · scores[i]ᵀ
    r.matmul(*v.buffer, *scores.buffer, *out.buffer,
             {v.c, n, l, v.offset(), l, 1, scores.offset(), 1, l, out.offset() + r0, l, 1, -1, kActNone, 1.f});
  }
}

}  // namespace neuflow::model::vulkan
