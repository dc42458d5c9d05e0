#include <opencv2/imgproc.hpp>

#include "ops/cpu_op.hpp"

namespace neuflow::model {

// OpenCV's area resize at an exact factor of two is the 2×2 box filter.
std::unique_ptr<CpuOp> build_op(const graph::AvgPool2x& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    const Tensor& src = pass.tensors.nhwc(op.in.tensor);
    Tensor& dst = pass.tensors.nhwc(op.out.tensor);
    const cv::Mat s(src.h, src.w, CV_32FC(src.c), const_cast<float*>(src.data.data()));
    cv::Mat d(dst.h, dst.w, CV_32FC(dst.c), dst.data.data());
    cv::resize(s, d, d.size(), 0, 0, cv::INTER_AREA);
  });
}

}  // namespace neuflow::model
