#include "dnnl/context.hpp"

namespace neuflow::model {

const dnnl::engine& cpu_engine() {
  static const dnnl::engine engine(dnnl::engine::kind::cpu, 0);
  return engine;
}

dnnl::memory::desc nhwc_desc(int h, int w, int c) {
  return dnnl::memory::desc({1, c, h, w}, dnnl::memory::data_type::f32, dnnl::memory::format_tag::nhwc);
}

dnnl::memory wrap_nhwc(Tensor& t) { return dnnl::memory(nhwc_desc(t.h, t.w, t.c), cpu_engine(), t.data.data()); }

}  // namespace neuflow::model
