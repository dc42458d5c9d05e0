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

}  // namespace neuflow::model::vulkan
