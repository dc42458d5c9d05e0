#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// The flow reaches the host as the convex upsampling's dispatch writes it into the ring entry's
// read-back buffer (convex_upsample.comp): nothing is copied or converted after it.
void record_op(Recorder& r, const graph::Output& op) {
  if (r.handed_out() != op.flow.tensor || op.flow.channel != 0 || op.flow.c != 2) {
    throw std::logic_error("the Vulkan backend hands out only the flow of a convex upsampling, not " +
                           r.tensors().at(op.flow.tensor).name);
  }
  r.host_barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
}

}  // namespace neuflow::model::vulkan
