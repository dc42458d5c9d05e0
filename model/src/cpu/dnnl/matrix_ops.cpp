#include "dnnl/matrix_ops.hpp"

#include <stdexcept>

#include "dnnl/context.hpp"

namespace neuflow::model {

using dnnl::memory;
using dt = dnnl::memory::data_type;

void matmul(dnnl::stream& stream, MatrixView a, MatrixView b, float* c, int ldc, const MatmulOptions& options) {
  const bool transpose_b = options.transpose_b;
  // oneDNN's output scale and bias compose differently across versions; we never need both.
  if (options.alpha != 1.f && options.bias) throw std::logic_error("matmul: alpha with bias is not supported");
  const float* bias = options.bias;
  const auto& eng = cpu_engine();
  const memory::dim m = a.rows, k = a.cols;
  const memory::dim n = transpose_b ? b.rows : b.cols;
  if ((transpose_b ? b.cols : b.rows) != k) throw std::logic_error("matmul: inner dimensions differ");
  const memory::desc a_md({m, k}, dt::f32, memory::dims{a.ld, 1});
  const memory::desc b_md({k, n}, dt::f32, transpose_b ? memory::dims{1, b.ld} : memory::dims{b.ld, 1});
  const memory::desc c_md({m, n}, dt::f32, memory::dims{ldc, 1});
  const memory::desc bias_md = bias ? memory::desc({1, n}, dt::f32, memory::dims{n, 1}) : memory::desc();
  dnnl::primitive_attr attr;
  if (options.alpha != 1.f) attr.set_output_scales(0, {options.alpha});
  if (options.gelu) {
    dnnl::post_ops ops;
    ops.append_eltwise(1.f, dnnl::algorithm::eltwise_gelu_erf, 0.f, 0.f);
    attr.set_post_ops(ops);
  }
  const dnnl::matmul::primitive_desc pd(dnnl::matmul::desc(a_md, b_md, bias_md, c_md), attr, eng);
  std::unordered_map<int, memory> args{{DNNL_ARG_SRC, memory(a_md, eng, const_cast<float*>(a.data))},
                                       {DNNL_ARG_WEIGHTS, memory(b_md, eng, const_cast<float*>(b.data))},
                                       {DNNL_ARG_DST, memory(c_md, eng, c)}};
  if (bias) args.emplace(DNNL_ARG_BIAS, memory(bias_md, eng, const_cast<float*>(bias)));
  dnnl::matmul(pd).execute(stream, args);
}

namespace {

void softmax(dnnl::stream& stream, float* data, int rows, int cols, int axis) {
  const auto& eng = cpu_engine();
  const memory::desc md({rows, cols}, dt::f32, memory::format_tag::ab);
  const dnnl::softmax_forward::primitive_desc pd(
      dnnl::softmax_forward::desc(dnnl::prop_kind::forward_inference, md, axis), eng);
  memory mem(md, eng, data);
  dnnl::softmax_forward(pd).execute(stream, {{DNNL_ARG_SRC, mem}, {DNNL_ARG_DST, mem}});
}

}  // namespace

void softmax_rows(dnnl::stream& stream, float* data, int rows, int cols) { softmax(stream, data, rows, cols, 1); }

void exp_in_place(dnnl::stream& stream, float* data, std::size_t count) {
  const auto& eng = cpu_engine();
  const memory::desc md({static_cast<memory::dim>(count)}, dt::f32, memory::format_tag::a);
  const dnnl::eltwise_forward::primitive_desc pd(
      dnnl::eltwise_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::eltwise_exp, md), eng);
  memory mem(md, eng, data);
  dnnl::eltwise_forward(pd).execute(stream, {{DNNL_ARG_SRC, mem}, {DNNL_ARG_DST, mem}});
}

}  // namespace neuflow::model
