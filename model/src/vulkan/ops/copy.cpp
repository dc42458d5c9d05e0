#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// Channel ranges are contiguous in the planar layout: one buffer copy.
void record_op(Recorder& r, const graph::Copy& op) { r.copy(r.view(op.in), r.view(op.out)); }

}  // namespace neuflow::model::vulkan
