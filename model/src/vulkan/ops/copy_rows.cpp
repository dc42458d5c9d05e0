#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// A channel's rows are contiguous in the planar layout: one copy command, a region a channel.
void record_op(Recorder& r, const graph::CopyRows& op) {
  r.copy_rows(r.view(op.in), r.view(op.out), op.in_row, op.out_row, op.rows);
}

}  // namespace neuflow::model::vulkan
