#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

namespace {

void record_resample(Recorder& r, const graph::Resample& op, const graph::Resample* second) {
  const View in = r.view(op.in), out = r.view(op.out);
  const View in2 = second ? r.view(second->in) : View{};
  ResampleParams p{.channels = in.c,
                   .in_h = in.h,
                   .in_w = in.w,
                   .in_off = in.offset(),
                   .out_off = out.offset(),
                   .factor = op.factor,
                   .relu = op.relu ? 1 : 0,
                   .scale = op.scale,
                   .channels2 = 0,
                   .in2_h = 1,
                   .in2_w = 1,
                   .in2_off = 0,
                   .factor2 = 1,
                   .relu2 = 0,
                   .scale2 = 1.f};
  long long read = in.count(), written = out.count();
  if (second) {
    p.channels2 = in2.c;
    p.in2_h = in2.h;
    p.in2_w = in2.w;
    p.in2_off = in2.offset();
    p.factor2 = second->factor;
    p.relu2 = second->relu ? 1 : 0;
    p.scale2 = second->scale;
    read += in2.count();
    written += r.view(second->out).count();
  }
  r.dispatch<Shader::resample>({in.buffer, second ? in2.buffer : nullptr, out.buffer, nullptr}, p,
                               {r.bytes(read), r.bytes(written), 0}, groups(written, kLocal));
}

}  // namespace

void record_op(Recorder& r, const graph::Resample& op) { record_resample(r, op, nullptr); }

void record_op(Recorder& r, const graph::Resample& first, const graph::Resample& second) {
  if (second.out.tensor != first.out.tensor || second.out.channel != first.out.channel + first.out.c) {
    throw std::logic_error("the Vulkan concatenation's second part does not follow its first");
  }
  record_resample(r, first, &second);
}

}  // namespace neuflow::model::vulkan
