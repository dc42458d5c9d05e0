#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::Zero& op) { r.zero(r.view(op.out)); }

}  // namespace neuflow::model::vulkan
