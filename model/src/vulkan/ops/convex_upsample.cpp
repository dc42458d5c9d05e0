#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::ConvexUpsample& op) {
  const View mask = r.view(op.mask), flow = r.view(op.flow), out = r.view(op.out);
  require_whole(mask, "convex upsampling");
  require_whole(flow, "convex upsampling");
  require_whole(out, "convex upsampling");
  r.dispatch<Shader::convex_upsample>({mask.buffer, flow.buffer, out.buffer, nullptr},
                                      ConvexUpsampleParams{flow.h, flow.w},
                                      {r.bytes(mask.count() + flow.count()), r.bytes(out.count()), 9LL * out.count()},
                                      groups(static_cast<long>(out.h) * out.w, kLocal));
}

}  // namespace neuflow::model::vulkan
