#include <algorithm>
#include <stdexcept>

#include "vulkan/ops/record_op.hpp"
#include "vulkan/ops/winograd.hpp"
#include "vulkan/product_kernels.hpp"

namespace neuflow::model::vulkan {

// A refinement step's end beside its conv3, in one dispatch (winograd_conv.comp and
// winograd_conv_fragments.comp with STEP_CORRELATION): conv3 for the hidden state only, its
// output channels 2-65 clamped straight into the next step input, in the one-dispatch Winograd
// form the network runs; beside it, in workgroups of their own, conv3's two delta channels
// computed directly and the new flow, then either the next step's correlation (as
// local_correlation_update does after conv3: winograd_conv_step) or, at a scale's last step,
// the new flow resampled (as refine_update does: winograd_conv_step_end). Neither half reads what
// the other writes, so the step's last two dispatches and the barrier between them are one, and
// conv3's 66 channels are never written.

namespace {

// The parameters and the counts of both forms; `corr`: the next step's correlation (nullptr at a
// scale's last step, which resamples the flow into `resampled` where `then` is given).
void record_step_end(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& update,
                     const graph::LocalCorrelation* corr, const graph::Resample* then) {
  const DeviceConv& w = *conv3.weights;
  const View in = r.view(conv3.in), out = r.view(conv3.out), hidden = r.view(update.hidden),
             flow_copy = r.view(update.flow_copy), flow = r.view(update.flow);
  const View f0 = corr ? r.view(corr->f0) : View{}, f1 = corr ? r.view(corr->f1) : View{},
             corr_out = corr ? r.view(corr->out) : View{};
  const View resampled = resampled_flow(r, update, then);
  if (!takes_winograd(r.conv_algorithm(), conv3, out.h, out.w) || r.conv_algorithm() == ConvAlgorithm::winograd_split ||
      out.c != 66 || hidden.c != 64 || flow_copy.c != 2 || w.bias.offset < 0 || conv3.addend ||
      conv3.act != Activation::none || hidden.buffer != flow_copy.buffer || hidden.h != out.h || hidden.w != out.w ||
      (corr && (corr_out.buffer != hidden.buffer || corr->flow.tensor != update.flow.tensor))) {
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
  const int step_groups = static_cast<int>(
      std::min<long>((plane + kStepCorrelationPixels - 1) / kStepCorrelationPixels, 65535 - conv_groups));
  const WinogradConvStepParams p{
      in.c,
      out.h,
      out.w,
      in.offset(),
      hidden.c,
      hidden.offset(),
      tiles_x,
      tile_count,
      w.weight.offset + 2 * 9 * in.c,                                            // the hidden state's filters (scalar)
      scalar ? -1 : r.device_weights().winograd_filters_of(w) + 2 * filters_in,  // ... transformed
      filters_in,
      winograd_filter_side(out.c),  // the transformed filters' stride
      w.bias.offset + 2,
      -1,
      kActClamp4,
      conv_groups,
      tile_groups,
      corr ? f0.c : 0,
      corr ? f0.offset() : 0,
      corr ? f1.offset() : 0,
      flow.offset(),
      corr ? corr_out.offset() : 0,
      flow_copy.offset(),
      w.weight.offset,
      w.bias.offset,
      then ? resampled.offset() : -1,
      then ? then->factor : 1,
      then ? then->scale : 1.f};
  const long long delta_taps = 2LL * 9 * in.c;
  const long long conv_reads =
      scalar ? r.bytes(in.count() + 9LL * in.c * hidden.c + hidden.c)
             : r.bytes(in.count() + hidden.c) + 2LL * 36 * winograd_filter_side(hidden.c) * filters_in;
  const long long read =
      conv_reads + r.bytes(in.count() + delta_taps + 2 + flow.count() + (corr ? f0.count() + f1.count() : 0));
  const long long written = r.bytes(hidden.count() + flow_copy.count() + flow.count() + (corr ? corr_out.count() : 0) +
                                    (then ? resampled.count() : 0));
  const long long multiply_adds = 36LL * hidden.c * in.c * tile_count + delta_taps * plane +
                                  (corr ? static_cast<long long>(corr_out.count()) * f0.c : 0);
  const Buffer* filters = scalar ? nullptr : &r.device_weights().winograd_buffer;
  const Shader shader =
      product_shader(corr ? Shader::winograd_conv_step : Shader::winograd_conv_step_end, r.product_kernels());
  r.record_dispatch(shader,
                    {&r.weights(), in.buffer, hidden.buffer, nullptr, filters,
                     corr ? f0.buffer : (then ? resampled.buffer : nullptr), corr ? f1.buffer : nullptr, flow.buffer},
                    &p, sizeof p, {read, written, multiply_adds},
                    {static_cast<uint32_t>(conv_groups + step_groups), 1, 1});
}

}  // namespace

void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& previous,
               const graph::LocalCorrelation& op) {
  record_step_end(r, conv3, previous, &op, nullptr);
}

void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& op,
               const graph::Resample* then) {
  record_step_end(r, conv3, op, nullptr, then);
}

}  // namespace neuflow::model::vulkan
