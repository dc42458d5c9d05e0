#include "dnnl/conv_op.hpp"

#include <cstring>
#include <stdexcept>
#include <utility>

#include "dnnl/context.hpp"

namespace neuflow::model {

using dnnl::memory;
using tag = dnnl::memory::format_tag;
using dt = dnnl::memory::data_type;

namespace {

dnnl::primitive_attr make_attr(const ConvParams& p) {
  dnnl::post_ops ops;
  if (p.accumulate) ops.append_sum(1.f);
  switch (p.activation) {
    case Activation::none: break;
    case Activation::leaky_relu: ops.append_eltwise(1.f, dnnl::algorithm::eltwise_relu, 0.1f, 0.f); break;
    case Activation::relu: ops.append_eltwise(1.f, dnnl::algorithm::eltwise_relu, 0.f, 0.f); break;
    case Activation::gelu: ops.append_eltwise(1.f, dnnl::algorithm::eltwise_gelu_erf, 0.f, 0.f); break;
  }
  dnnl::primitive_attr attr;
  attr.set_post_ops(ops);
  return attr;
}

// Where Winograd measured faster than oneDNN's direct convolution (docs/benchmarks.md,
// "Winograd", neuflow-bench-conv): every layer it computes (stride-1 3×3, and the 6×6
// stride-2 one by space-to-depth) with at least this many input channels.
constexpr int kWinogradMinInputChannels = 32;

// The layout of `d` if Winograd reads and writes it in place.
std::optional<ChannelLayout> winograd_layout(const memory::desc& d) {
  const auto dims = d.dims();
  if (dims.size() != 4) return std::nullopt;
  for (const auto& [t, layout] :
       {std::pair{tag::nhwc, ChannelLayout::nhwc}, std::pair{tag::nChw8c, ChannelLayout::blocked8},
        std::pair{tag::nChw16c, ChannelLayout::blocked16}}) {
    if (d == memory::desc(dims, dt::f32, t)) return layout;
  }
  return std::nullopt;
}

// The blocked layout oneDNN's own convolutions pick on this CPU, so a Winograd layer between
// them needs no reorder: 16 channels a block with AVX-512, 8 with AVX2.
memory::format_tag preferred_blocking() {
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx512f")) return tag::nChw16c;
#endif
  return tag::nChw8c;
}

bool use_winograd(const ConvWeights& w, const ConvParams& p, int height, int width, CpuConvolution choice,
                  const std::optional<memory::desc>& output) {
  if (choice == CpuConvolution::direct || !WinogradConv::handles(w, p, height, width)) return false;
  if (output && !winograd_layout(*output)) return false;
  return choice != CpuConvolution::automatic || w.in_channels >= kWinogradMinInputChannels;
}

// On layers that run several times a pair, F(6×6, 3×3) where its share of the products is
// smaller and F(4×4, 3×3) where its tiles fit the image with less overhang; F(4×4) elsewhere
// (see ConvParams::repeated). Both stay within the error bound of
// tests/model/winograd_conv_test.cpp. (height, width: the output's; a strided layer's
// products have s² times its input channels.)
WinogradTile winograd_tile(CpuConvolution choice, const ConvWeights& w, const ConvParams& p, int height, int width) {
  if (choice == CpuConvolution::winograd4 || (choice != CpuConvolution::winograd6 && !p.repeated)) {
    return WinogradTile::f4x4;
  }
  if (choice == CpuConvolution::winograd6) return WinogradTile::f6x6;
  return WinogradConv::faster_tile(w.in_channels * p.stride * p.stride, w.out_channels, height, width);
}

// In the arena, or without memory until set_output() gives it some.
memory output_memory(const memory::desc& desc, ScratchArena& arena, bool own_output) {
  return own_output ? arena.make(desc) : memory(desc, cpu_engine(), DNNL_MEMORY_NONE);
}

}  // namespace

ConvOp::ConvOp(const ConvWeights& w, const ConvParams& p, const memory::desc& input, PlanContext& context,
               std::optional<memory::desc> output, bool own_output)
    : accumulate_(p.accumulate) {
  ScratchArena& arena = context.arena;
  const auto& eng = cpu_engine();
  const auto dims = input.dims();  // {1, C, H, W}
  if (dims.size() != 4 || dims[1] != w.in_channels) {
    throw std::logic_error("ConvOp: input channels do not match the weights");
  }
  const int in_h = static_cast<int>(dims[2]);
  const int in_w = static_cast<int>(dims[3]);
  out_c_ = w.out_channels;
  out_h_ = (in_h + 2 * p.pad - w.kernel_h) / p.stride + 1;
  out_w_ = (in_w + 2 * p.pad - w.kernel_w) / p.stride + 1;

  if (use_winograd(w, p, in_h, in_w, context.convolution, output)) {
    const memory::desc out_desc =
        output ? *output : memory::desc({1, out_c_, out_h_, out_w_}, dt::f32, preferred_blocking());
    memory::desc in_desc = input;
    if (!winograd_layout(input)) {  // not one it reads in place
      in_desc = memory::desc({1, w.in_channels, in_h, in_w}, dt::f32, preferred_blocking());
      reordered_input_ = arena.make(in_desc);
      input_reorder_ = dnnl::reorder(dnnl::reorder::primitive_desc(eng, input, eng, in_desc));
    }
    // GELU (erf) is applied afterwards by oneDNN's vectorized eltwise, in place: the output
    // transform's scalar erf cost more than the convolution it follows.
    ConvParams winograd_params = p;
    if (p.activation == Activation::gelu) {
      winograd_params.activation = Activation::none;
      gelu_ = dnnl::eltwise_forward(dnnl::eltwise_forward::primitive_desc(
          dnnl::eltwise_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::eltwise_gelu_erf, out_desc),
          eng));
    }
    winograd_.emplace(w, winograd_params, in_h, in_w, *winograd_layout(in_desc), *winograd_layout(out_desc),
                      winograd_tile(context.convolution, w, p, out_h_, out_w_), arena);
    dst_ = output_memory(out_desc, arena, own_output);
    return;
  }

  const memory::dims src_dims{1, w.in_channels, in_h, in_w};
  const memory::dims wei_dims{w.out_channels, w.in_channels, w.kernel_h, w.kernel_w};
  const memory::dims dst_dims{1, out_c_, out_h_, out_w_};
  const memory::desc src_any(src_dims, dt::f32, tag::any);
  const memory::desc wei_any(wei_dims, dt::f32, tag::any);
  const memory::desc dst_md = output ? *output : memory::desc(dst_dims, dt::f32, tag::any);
  const memory::desc bias_md = w.bias.empty() ? memory::desc() : memory::desc({out_c_}, dt::f32, tag::x);

  const auto desc =
      dnnl::convolution_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::convolution_direct, src_any,
                                      wei_any, bias_md, dst_md, {p.stride, p.stride}, {p.pad, p.pad}, {p.pad, p.pad});
  const dnnl::convolution_forward::primitive_desc pd(desc, make_attr(p), eng);
  conv_ = dnnl::convolution_forward(pd);

  // Weights: reorder once from the checkpoint's OIHW into the primitive's layout.
  dnnl::stream s(eng);
  memory user_w({wei_dims, dt::f32, tag::oihw}, eng, const_cast<float*>(w.weight.data()));
  weights_ = memory(pd.weights_desc(), eng);
  dnnl::reorder(user_w, weights_).execute(s, user_w, weights_);
  if (!w.bias.empty()) {
    bias_ = memory(bias_md, eng);
    std::memcpy(bias_.get_data_handle(), w.bias.data(), w.bias.size() * sizeof(float));
  }
  s.wait();

  dst_ = output_memory(pd.dst_desc(), arena, own_output);
  if (pd.src_desc() != input) {
    reordered_input_ = arena.make(pd.src_desc());
    input_reorder_ = dnnl::reorder(dnnl::reorder::primitive_desc(eng, input, eng, pd.src_desc()));
  }
}

const memory& ConvOp::run(dnnl::stream& stream, const memory& input, const memory* addend) {
  if (accumulate_ != (addend != nullptr)) throw std::logic_error("ConvOp: addend given iff accumulate");
  const memory* src = &input;
  if (input_reorder_) {
    memory in = input;  // a handle copy: reorder::execute takes non-const handles
    input_reorder_->execute(stream, in, reordered_input_);
    src = &reordered_input_;
  }
  if (winograd_) {
    if (addend && addend->get_desc() != dst_.get_desc()) throw std::logic_error("ConvOp: addend layout differs");
    winograd_->run(static_cast<const float*>(src->get_data_handle()),
                   addend ? static_cast<const float*>(addend->get_data_handle()) : nullptr,
                   static_cast<float*>(dst_.get_data_handle()));
    if (gelu_) gelu_->execute(stream, {{DNNL_ARG_SRC, dst_}, {DNNL_ARG_DST, dst_}});
    return dst_;
  }
  if (addend) {
    std::memcpy(dst_.get_data_handle(), addend->get_data_handle(), dst_.get_desc().get_size());
  }
  std::unordered_map<int, memory> args{{DNNL_ARG_SRC, *src}, {DNNL_ARG_WEIGHTS, weights_}, {DNNL_ARG_DST, dst_}};
  if (bias_) args.emplace(DNNL_ARG_BIAS, bias_);
  conv_.execute(stream, args);
  return dst_;
}

void ConvOp::run_to_nhwc(dnnl::stream& stream, const memory& input, Tensor& out, const memory* addend) {
  run(stream, input, addend);
  if (out.h != out_h_ || out.w != out_w_ || out.c != out_c_) out.resize(out_h_, out_w_, out_c_);
  memory out_mem(nhwc_desc(out_h_, out_w_, out_c_), cpu_engine(), out.data.data());
  if (!nhwc_reorder_) nhwc_reorder_ = dnnl::reorder(dst_, out_mem);
  nhwc_reorder_->execute(stream, dst_, out_mem);
}

void to_nhwc(dnnl::stream& stream, const memory& src, Tensor& out) {
  const auto dims = src.get_desc().dims();
  const int c = static_cast<int>(dims[1]), h = static_cast<int>(dims[2]), w = static_cast<int>(dims[3]);
  if (out.h != h || out.w != w || out.c != c) out.resize(h, w, c);
  memory out_mem(nhwc_desc(h, w, c), cpu_engine(), out.data.data());
  memory in = src;
  dnnl::reorder(in, out_mem).execute(stream, in, out_mem);
}

}  // namespace neuflow::model
