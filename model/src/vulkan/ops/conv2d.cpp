#include <bit>

#include "vulkan/ops/record_op.hpp"
#include "vulkan/ops/winograd.hpp"

namespace neuflow::model::vulkan {

namespace {

// Where a one-dispatch Winograd convolution reads its input: the input tensor (binding 1), or
// the parts of its concatenation (bindings 1 and 5), and how many values that is.
struct WinogradInput {
  const Buffer* first = nullptr;
  const Buffer* second = nullptr;
  long long values = 0;
};

// log2 of a resample's factor (a power of two: ConvInputParts' condition).
int factor_shift(int factor) { return std::countr_zero(static_cast<unsigned>(factor)); }

// The parameters of both one-dispatch forms: winograd_conv.comp reads the OIHW filters at w_off,
// winograd_conv_fragments.comp the filters transformed at upload. The input from `parts` where
// given (nullptr: from `in`).
WinogradConvParams winograd_conv_params(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const View& in,
                                        const View& out, const View& addend, const ConvInputParts* parts,
                                        WinogradInput& input) {
  const DeviceConv& w = *op.weights;
  const int tiles_x = winograd_tiles(out.w);
  WinogradConvParams p{in.c,
                       in.h,
                       in.w,
                       in.offset(),
                       out.c,
                       out.offset(),
                       tiles_x,
                       tiles_x * winograd_tiles(out.h),
                       w.weight.offset,
                       r.device_weights().winograd_filters_of(w),
                       winograd_filter_side(in.c),
                       winograd_filter_side(out.c),
                       w.bias.offset,
                       op.addend ? addend.offset() : -1,
                       activation_code(op.act),
                       in.c,
                       0,
                       0,
                       0,
                       0,
                       1.f,
                       1.f};
  input = {in.buffer, nullptr, in.count()};
  if (!parts) return p;
  const View first = r.view(parts->first.in);
  p.in_off = first.offset();
  p.part_c = first.c;
  p.shift = factor_shift(parts->first.factor);
  p.relu_parts = parts->first.relu ? 1 : 0;
  p.scale = parts->first.scale;
  input = {first.buffer, nullptr, first.count()};
  if (parts->second) {
    const View second = r.view(parts->second->in);
    p.in2_off = second.offset();
    p.shift2 = factor_shift(parts->second->factor);
    p.relu_parts |= parts->second->relu ? 2 : 0;
    p.scale2 = parts->second->scale;
    input.second = second.buffer;
    input.values += second.count();
  }
  return p;
}

// F(4×4, 3×3) in one dispatch (winograd_conv.comp): the filters and tiles transformed as they
// are loaded, the products transformed back with bias, addend and activation as they are
// stored. It reads what the direct convolution reads (`others`: the filters, bias and addend
// values besides the input; the input from its parts where it reads them) and writes what it
// writes.
void record_winograd_fused(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const View& in, const View& out,
                           const View& addend, long long others, const ConvInputParts* parts) {
  WinogradInput input;
  const WinogradConvParams p = winograd_conv_params(r, op, in, out, addend, parts, input);
  const long long points = 36LL * out.c * in.c;
  r.record_dispatch(parts ? Shader::winograd_conv_parts : Shader::winograd_conv,
                    {&r.weights(), input.first, out.buffer, addend.buffer, nullptr, input.second}, &p, sizeof p,
                    {r.bytes(input.values + others), r.bytes(out.count()), points * p.tiles},
                    {tiles(p.tiles, "a convolution", 32), tiles(out.c, "a convolution", 16), 1});
}

// F(4×4, 3×3) in one dispatch with the products on fragments (winograd_conv_fragments.comp, on
// tensor cores or their twin): the tiles transformed as they are loaded, the filters as
// transformed at upload (fp16, padded to 16), the products transformed back with bias, addend
// and activation as they are stored. `others`: the bias and addend values it reads besides the
// input and the filters.
void record_winograd_fragments(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const View& in, const View& out,
                               const View& addend, long long others, const ConvInputParts* parts) {
  WinogradInput input;
  const WinogradConvParams p = winograd_conv_params(r, op, in, out, addend, parts, input);
  const long long filters = 36LL * p.filters_out * p.filters_in;  // fp16, as the fragments load them
  r.record_dispatch(
      product_shader(parts ? Shader::winograd_conv_parts : Shader::winograd_conv, r.product_kernels()),
      {&r.weights(), input.first, out.buffer, addend.buffer, &r.device_weights().winograd_buffer, input.second}, &p,
      sizeof p, {r.bytes(input.values + others) + filters * 2, r.bytes(out.count()), 36LL * out.c * in.c * p.tiles},
      {tiles(p.tiles, "a convolution", 16), tiles(out.c, "a convolution", 16), 1});
}

// F(4×4, 3×3) in three dispatches: the input tiles transformed, 36 products of the filters
// transformed at upload by those tiles, the products transformed back with bias, addend and
// activation. A quarter of the direct convolution's multiply-adds, at the cost of moving the
// tiles and products (fp32) through memory.
void record_winograd(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const View& in, const View& out,
                     const View& addend) {
  const DeviceConv& w = *op.weights;
  const int tiles_x = winograd_tiles(out.w), tile_count = tiles_x * winograd_tiles(out.h);
  const long long points = 36LL * in.c * tile_count, products = 36LL * out.c * tile_count;
  const auto fp32 = [](long long values) { return values * static_cast<long long>(sizeof(float)); };
  r.dispatch<Shader::winograd_input>({in.buffer, nullptr, &r.winograd_points(), nullptr},
                                     WinogradInputParams{in.c, in.h, in.w, in.offset(), tiles_x, tile_count},
                                     {r.bytes(in.count()), fp32(points), 0},
                                     groups(static_cast<long>(in.c) * tile_count, kLocal));
  const long long filters = 36LL * out.c * in.c;
  r.product<Shader::winograd_gemm>(
      {&r.device_weights().winograd_buffer, &r.winograd_points(), &r.winograd_products(), nullptr},
      WinogradGemmParams{out.c, tile_count, in.c, r.device_weights().winograd_filters_of(w), winograd_filter_side(in.c),
                         winograd_filter_side(out.c)},
      {r.bytes(filters) + fp32(points), fp32(products), filters * tile_count}, out.c, tile_count, "a convolution", 36);
  const WinogradOutputParams p{out.c,
                               out.h,
                               out.w,
                               out.offset(),
                               tiles_x,
                               tile_count,
                               w.bias.offset,
                               op.addend ? addend.offset() : -1,
                               activation_code(op.act)};
  const long long read = fp32(products) + r.bytes((w.bias.offset >= 0 ? out.c : 0) + (op.addend ? out.count() : 0));
  r.dispatch<Shader::winograd_output>({&r.weights(), &r.winograd_products(), out.buffer, addend.buffer}, p,
                                      {read, r.bytes(out.count()), 0},
                                      groups(static_cast<long>(out.c) * tile_count, kLocal));
}

// A one-dispatch convolution reads its input (or its parts: each part's buffer whole) and addend
// and writes its output exactly where their views lie.
void touches_only_its_views(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const View& in, const View& out,
                            const View& addend, const ConvInputParts* parts) {
  if (!parts) r.touches_only(1, in);
  r.touches_only(2, out);
  if (op.addend) r.touches_only(3, addend);
}

// F(4×4, 3×3) in one dispatch on the kernels the network runs its products on, the input from
// `parts` where given (nullptr: from op.in).
void record_winograd_one_dispatch(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const ConvInputParts* parts) {
  const View in = r.view(op.in), out = r.view(op.out);
  const View addend = op.addend ? r.view(*op.addend) : View{};
  const long long others = (op.weights->bias.offset >= 0 ? out.c : 0) + (op.addend ? out.count() : 0);
  touches_only_its_views(r, op, in, out, addend, parts);
  if (r.product_kernels() != ProductKernels::scalar) {
    record_winograd_fragments(r, op, in, out, addend, others, parts);
  } else {
    record_winograd_fused(r, op, in, out, addend, others + 9LL * in.c * out.c, parts);  // and the 3×3 filters
  }
}

}  // namespace

void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const ConvInputParts& parts) {
  if (!reads_input_in_parts(r.conv_algorithm(), op, r.tensors())) {
    throw std::logic_error("the Vulkan " + op.layer + " does not read its input in parts");
  }
  record_winograd_one_dispatch(r, op, &parts);
}

// Stride-1 3×3 convolutions by Winograd where takes_winograd() says so, fused or split as the
// network runs them; the rest by the implicit-GEMM convolution (matmul.comp with IMPLICIT_CONV).
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& op) {
  const DeviceConv& w = *op.weights;
  const View in = r.view(op.in), out = r.view(op.out);
  const View addend = op.addend ? r.view(*op.addend) : View{};
  const long long taps = static_cast<long long>(in.c) * w.kernel_h * w.kernel_w;
  const long long others = (w.bias.offset >= 0 ? out.c : 0) + (op.addend ? out.count() : 0);
  const long long read = in.count() + others + taps * out.c;
  if (takes_winograd(r.conv_algorithm(), op, out.h, out.w)) {
    if (r.conv_algorithm() == ConvAlgorithm::winograd_split) {
      record_winograd(r, op, in, out, addend);
    } else {
      record_winograd_one_dispatch(r, op, nullptr);
    }
    return;
  }
  const Conv2dParams p{in.c,
                       in.h,
                       in.w,
                       in.offset(),
                       out.c,
                       out.h,
                       out.w,
                       out.offset(),
                       w.kernel_h,
                       op.stride,
                       op.pad,
                       activation_code(op.act),
                       w.weight.offset,
                       w.bias.offset,
                       op.addend ? addend.offset() : -1,
                       1.f};
  touches_only_its_views(r, op, in, out, addend, nullptr);
  r.product<Shader::conv2d>({&r.weights(), in.buffer, out.buffer, addend.buffer}, p,
                            {r.bytes(read), r.bytes(out.count()), taps * out.count()}, out.c,
                            static_cast<long>(out.h) * out.w, "a convolution");
}

}  // namespace neuflow::model::vulkan
