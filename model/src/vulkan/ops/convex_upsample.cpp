#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::ConvexUpsample& op, bool planar) {
  const View mask = r.view(op.mask), flow = r.view(op.flow), out = r.view(op.out);
  require_whole(mask, "convex upsampling");
  require_whole(flow, "convex upsampling");
  require_whole(out, "convex upsampling");
  const long long handed_out = static_cast<long long>(sizeof(float)) * out.count();
  r.dispatch<Shader::convex_upsample>(
      {mask.buffer, flow.buffer, &r.flow_out(), planar ? out.buffer : nullptr},
      ConvexUpsampleParams{flow.h, flow.w, planar ? 1 : 0},
      {r.bytes(mask.count() + flow.count()), handed_out + (planar ? r.bytes(out.count()) : 0), 9LL * out.count()},
      groups(static_cast<long>(out.h) * out.w, kLocal));
  r.handed_out(op.out.tensor);
}

}  // namespace neuflow::model::vulkan
