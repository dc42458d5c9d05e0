#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// With an observer, each tensor read back at this point of the pass; without, a timestamp.
void record_op(Recorder& r, const graph::StageEnd& op) {
  if (!r.observing()) {
    r.mark(op.name);
    return;
  }
  for (const auto& o : op.observed) r.observe(o.name, o.frame, r.view(o.tensor));
}

}  // namespace neuflow::model::vulkan
