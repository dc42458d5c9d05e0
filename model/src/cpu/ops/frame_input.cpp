#include <algorithm>
#include <stdexcept>

#include "ops/cpu_op.hpp"

namespace neuflow::model {

// The pass's image, unless it was converted straight into the input tensor (NetworkPlan::input()).
std::unique_ptr<CpuOp> build_op(const graph::FrameInput& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    Tensor& input = pass.tensors.nhwc(op.out.tensor);
    const Tensor* image = pass.image;
    if (!image || image->h != input.h || image->w != input.w || image->c != input.c) {
      throw std::logic_error("an encode pass without an image of the model's size");
    }
    if (image->data.data() != input.data.data()) std::copy(image->data.begin(), image->data.end(), input.data.begin());
  });
}

}  // namespace neuflow::model
