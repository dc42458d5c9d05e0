#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// Into the ring entry's read-back buffer, visible to the host once the pass's fence signals.
void record_op(Recorder& r, const graph::Output& op) { r.read_back(r.view(op.flow)); }

}  // namespace neuflow::model::vulkan
