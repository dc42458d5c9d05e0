#include <array>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::AvgPool2x& op) {
  const View in = r.view(op.in), out = r.view(op.out);
  require_whole(in, "average pooling");
  require_whole(out, "average pooling");
  r.dispatch<Shader::avgpool2x>({in.buffer, nullptr, out.buffer, nullptr}, Avgpool2xParams{in.c, in.h, in.w},
                                {r.bytes(in.count()), r.bytes(out.count()), 0}, groups(out.count(), kLocal));
}

// `ops` three poolings, each of the one before's output, of an input whose sides are multiples
// of 8: one dispatch.
void record_op(Recorder& r, const std::array<const graph::AvgPool2x*, 3>& ops) {
  const View in = r.view(ops[0]->in), half = r.view(ops[0]->out), quarter = r.view(ops[1]->out),
             eighth = r.view(ops[2]->out);
  for (const View* v : {&in, &half, &quarter, &eighth}) require_whole(*v, "average pooling");
  r.dispatch<Shader::avgpool_pyramid>(
      {in.buffer, nullptr, half.buffer, quarter.buffer, eighth.buffer}, AvgpoolPyramidParams{in.c, in.h, in.w},
      {r.bytes(in.count()), r.bytes(half.count() + quarter.count() + eighth.count()), 0},
      groups(eighth.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
