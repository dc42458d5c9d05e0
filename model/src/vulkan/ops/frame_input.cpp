#include <array>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// From the upload: an 8-bit frame converted and padded on the device, or floats already planar.
void record_op(Recorder& r, const graph::FrameInput& op) {
  const View out = r.view(op.out);
  require_whole(out, "frame input");
  if (const auto* f = r.frame_layout()) {
    const FrameU8Params p{f->width, f->height, out.w, out.h, f->pad_left, f->pad_top, f->swap ? 1 : 0};
    r.dispatch<Shader::frame_u8>({&r.upload(), nullptr, out.buffer, nullptr}, p,
                                 {3LL * f->width * f->height, r.bytes(out.count()), 0},
                                 groups(static_cast<long>(out.h) * out.w, kLocal));
  } else {
    r.copy_raw(r.upload(), *out.buffer, static_cast<std::size_t>(out.count()));
  }
}

void record_op(Recorder& r, const graph::FrameInput& op, const std::array<const graph::AvgPool2x*, 3>& pyramid) {
  const View out = r.view(op.out), half = r.view(pyramid[0]->out), quarter = r.view(pyramid[1]->out),
             eighth = r.view(pyramid[2]->out);
  for (const View* v : {&out, &half, &quarter, &eighth}) require_whole(*v, "frame input and its pyramid");
  const VulkanNetwork::FrameLayout& f = *r.frame_layout();
  const AvgpoolPyramidParams p{out.c, out.h, out.w, f.width, f.height, f.pad_left, f.pad_top, f.swap ? 1 : 0};
  r.dispatch<Shader::frame_pyramid>(
      {&r.upload(), out.buffer, half.buffer, quarter.buffer, eighth.buffer}, p,
      {3LL * f.width * f.height, r.bytes(out.count() + half.count() + quarter.count() + eighth.count()), 0},
      groups(eighth.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
