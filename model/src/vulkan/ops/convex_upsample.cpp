#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

static_assert(kGemmTile64.rows() == DeviceWeights::kConvexTileRows, "the mask's rows are ordered for 64-row tiles");

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

// The mask's product in 64×64 tiles of its reordered rows (DeviceWeights::convex_mask), each
// tile's sums then upsampling its 7 subpixels of 64 pixels (convex_upsample_tile.glsl).
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& mask, const graph::ConvexUpsample& op) {
  const DeviceConv& w = r.device_weights().convex_mask;
  const View in = r.view(mask.in), flow = r.view(op.flow), out = r.view(op.out);
  require_whole(flow, "convex upsampling");
  require_whole(out, "convex upsampling");
  if (mask.weights != &r.device_weights().upsample_conv3 || mask.stride != 1 || mask.pad != 0 ||
      mask.act != Activation::none || mask.addend || in.h != flow.h || in.w != flow.w) {
    throw std::logic_error("the Vulkan convex upsampling computes the mask of upsample_conv3 only, not of " +
                           mask.layer);
  }
  const Conv2dParams p{in.c,
                       in.h,
                       in.w,
                       in.offset(),
                       w.out_channels,
                       flow.h,
                       flow.w,
                       -1,
                       1,
                       1,
                       0,
                       activation_code(Activation::none),
                       w.weight.offset,
                       w.bias.offset,
                       flow.offset(),
                       1.f};
  const long plane = static_cast<long>(flow.h) * flow.w;
  // All the tiles' rows count, the zero ones included: they are multiplied all the same.
  const long long rows = w.out_channels;
  const long long read = in.count() + flow.count() + rows * (in.c + 1);
  const long long written = static_cast<long long>(sizeof(float)) * out.count();
  r.product<Shader::conv2d_convex>({&r.weights(), in.buffer, &r.flow_out(), flow.buffer}, p,
                                   {r.bytes(read), written, rows * plane * in.c + 9LL * out.count()}, w.out_channels,
                                   plane, "the upsampler's mask", 1, kGemmTile64);
  r.handed_out(op.out.tensor);
}

}  // namespace neuflow::model::vulkan
