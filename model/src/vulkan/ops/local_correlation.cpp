#include <algorithm>
#include <stdexcept>

#include "vulkan/ops/record_op.hpp"
#include "vulkan/ops/winograd.hpp"
#include "vulkan/product_kernels.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LocalCorrelation& op) { record_op(r, op, nullptr); }

namespace {

// The correlation in local_correlation_update.comp's form, which also writes the step input's
// hidden state and flow channels (`hidden`, `flow_copy`, in the output's buffer): from the
// previous step's update (`update`) or, without one, zeros and the flow as it is.
void record_with_step_input(Recorder& r, const graph::LocalCorrelation& op, const graph::Slice* update,
                            const graph::Slice& hidden_slice, const graph::Slice& flow_copy_slice) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  const View hidden = r.view(hidden_slice), flow_copy = r.view(flow_copy_slice);
  if (hidden.buffer != out.buffer || flow_copy.buffer != out.buffer || hidden.c != 64 || flow_copy.c != 2) {
    throw std::logic_error(
        "the Vulkan refinement step fuses its input's first values or its update only into a "
        "correlation of the same step input");
  }
  const View upd = update ? r.view(*update) : View{};
  const LocalCorrelationParams p{out.h,
                                 out.w,
                                 f0.c,
                                 f0.offset(),
                                 f1.offset(),
                                 flow.offset(),
                                 out.offset(),
                                 update ? upd.offset() : -1,
                                 hidden.offset(),
                                 flow_copy.offset()};
  // Without an update the flow is read, not written back.
  const long long read = f0.count() + f1.count() + flow.count() + (update ? upd.count() : 0);
  const long long written = out.count() + hidden.count() + flow_copy.count() + (update ? flow.count() : 0);
  r.dispatch<Shader::local_correlation_update>(
      {f0.buffer, f1.buffer, out.buffer, flow.buffer, upd.buffer}, p,
      {r.bytes(read), r.bytes(written), static_cast<long long>(out.count()) * f0.c},
      groups(static_cast<long>(out.h) * out.w, 16));
}

}  // namespace

// With `previous`, that step's update (refine_update.cpp's op) in the same dispatch: the hidden
// state, the flow's copy and the correlation share the step input's buffer.
void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::RefineUpdate* previous) {
  if (previous) {
    if (previous->flow.tensor != op.flow.tensor) {
      throw std::logic_error("the Vulkan refinement step fuses its update only into a correlation of its own flow");
    }
    record_with_step_input(r, op, &previous->update, previous->hidden, previous->flow_copy);
    return;
  }
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  const LocalCorrelationParams p{out.h, out.w, f0.c, f0.offset(), f1.offset(), flow.offset(), out.offset(), 0, 0, 0};
  r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, out.buffer, flow.buffer}, p,
                                        {r.bytes(f0.count() + f1.count() + flow.count()), r.bytes(out.count()),
                                         static_cast<long long>(out.count()) * f0.c},
                                        groups(static_cast<long>(out.h) * out.w, 16));
}

void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::Zero& hidden,
               const graph::Copy& flow_copy) {
  if (flow_copy.in.tensor != op.flow.tensor) {
    throw std::logic_error("the Vulkan refinement step starts its input only with its own flow");
  }
  record_with_step_input(r, op, nullptr, hidden.out, flow_copy.out);
}

// winograd_conv_step (winograd_conv.comp, winograd_conv_fragments.comp with STEP_CORRELATION):
// conv3 for the hidden state only, its output channels 2-65 clamped straight into the next step
// input, in the one-dispatch Winograd form the network runs; beside it, in workgroups of their
// own, conv3's two delta channels computed directly, the flow plus them, and the next step's
// correlation, as local_correlation_update does after conv3. Neither half reads what the other
// writes, so the step's last two dispatches and the barrier between them become one dispatch,
// and conv3's 66 channels are never written.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& update,
               const graph::LocalCorrelation& corr) {
  const DeviceConv& w = *conv3.weights;
  const View in = r.view(conv3.in), out = r.view(conv3.out), hidden = r.view(update.hidden),
             flow_copy = r.view(update.flow_copy), f0 = r.view(corr.f0), f1 = r.view(corr.f1), flow = r.view(corr.flow),
             corr_out = r.view(corr.out);
  if (!takes_winograd(r.conv_algorithm(), conv3, out.h, out.w) || r.conv_algorithm() == ConvAlgorithm::winograd_split ||
      out.c != 66 || hidden.c != 64 || flow_copy.c != 2 || w.bias.offset < 0 || conv3.addend ||
      conv3.act != Activation::none || hidden.buffer != corr_out.buffer || flow_copy.buffer != corr_out.buffer ||
      update.flow.tensor != corr.flow.tensor || corr_out.h != out.h || corr_out.w != out.w) {
    throw std::logic_error("the Vulkan " + conv3.layer +
                           " computes the refinement step's end beside it only as a one-dispatch Winograd "
                           "convolution into a step input of its own shape");
  }
  const bool scalar = r.product_kernels() == ProductKernels::scalar;
  const int tiles_x = winograd_tiles(out.w), tile_count = tiles_x * winograd_tiles(out.h);
  const int filters_in = winograd_filter_side(in.c);
  const int tile_groups = static_cast<int>(tiles(tile_count, "a convolution", scalar ? 32 : 16));
  const int conv_groups = tile_groups * static_cast<int>(tiles(hidden.c, "a convolution", 16));
  const long plane = static_cast<long>(out.h) * out.w;
  const int corr_groups = static_cast<int>(
      std::min<long>((plane + kStepCorrelationPixels - 1) / kStepCorrelationPixels, 65535 - conv_groups));
  const WinogradConvStepParams p{in.c,
                                 out.h,
                                 out.w,
                                 in.offset(),
                                 hidden.c,
                                 hidden.offset(),
                                 tiles_x,
                                 tile_count,
                                 w.weight.offset + 2 * 9 * in.c,  // the hidden state's filters (scalar)
                                 r.device_weights().winograd_filters_of(w) + 2 * filters_in,  // ... transformed
                                 filters_in,
                                 winograd_filter_side(out.c),  // the transformed filters' stride
                                 w.bias.offset + 2,
                                 -1,
                                 kActClamp4,
                                 conv_groups,
                                 tile_groups,
                                 f0.c,
                                 f0.offset(),
                                 f1.offset(),
                                 flow.offset(),
                                 corr_out.offset(),
                                 flow_copy.offset(),
                                 w.weight.offset,
                                 w.bias.offset};
  const long long delta_taps = 2LL * 9 * in.c;
  const long long conv_reads =
      scalar ? r.bytes(in.count() + 9LL * in.c * hidden.c + hidden.c)
             : r.bytes(in.count() + hidden.c) + 2LL * 36 * winograd_filter_side(hidden.c) * filters_in;
  const long long read = conv_reads + r.bytes(f0.count() + f1.count() + flow.count() + in.count() + delta_taps + 2);
  const long long written = r.bytes(hidden.count() + corr_out.count() + flow_copy.count() + flow.count());
  const long long multiply_adds =
      36LL * hidden.c * in.c * tile_count + delta_taps * plane + static_cast<long long>(corr_out.count()) * f0.c;
  r.record_dispatch(product_shader(Shader::winograd_conv_step, r.product_kernels()),
                    {&r.weights(), in.buffer, hidden.buffer, nullptr,
                     scalar ? nullptr : &r.device_weights().winograd_buffer, f0.buffer, f1.buffer, flow.buffer},
                    &p, sizeof p, {read, written, multiply_adds},
                    {static_cast<uint32_t>(conv_groups + corr_groups), 1, 1});
}

}  // namespace neuflow::model::vulkan
