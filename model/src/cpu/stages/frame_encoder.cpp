#include "stages/frame_encoder.hpp"

#include <opencv2/imgproc.hpp>

#include "dnnl/context.hpp"

namespace neuflow::model {

namespace {

// 2×2 average pooling; OpenCV's area resize at an exact factor of two is that box filter.
void avg_pool_2x(const Tensor& src, Tensor& dst) {
  dst.resize(src.h / 2, src.w / 2, src.c);
  const cv::Mat s(src.h, src.w, CV_32FC(src.c), const_cast<float*>(src.data.data()));
  cv::Mat d(dst.h, dst.w, CV_32FC(dst.c), dst.data.data());
  cv::resize(s, d, d.size(), 0, 0, cv::INTER_AREA);
}

dnnl::concat make_concat(const dnnl::memory::desc& a, const dnnl::memory::desc& b, dnnl::memory& dst,
                         PlanContext& context) {
  const dnnl::concat::primitive_desc pd(1, {a, b}, cpu_engine());
  dst = context.arena.make(pd.dst_desc());
  return dnnl::concat(pd);
}

}  // namespace

FrameEncoder::Block FrameEncoder::make_block(const ConvBlockWeights& w, int stride, int pad,
                                             const dnnl::memory::desc& input, PlanContext& context) {
  Block b;
  b.conv1.emplace(w.conv1, ConvParams{stride, pad, Activation::leaky_relu}, input, context);
  b.conv1->release_scratch(context.arena);
  b.conv2.emplace(w.conv2, ConvParams{1, 1, Activation::leaky_relu}, b.conv1->output_desc(), context);
  b.conv2->release_scratch(context.arena);
  context.arena.release(b.conv1->output());  // read by conv2 only
  return b;
}

const dnnl::memory& FrameEncoder::run_block(dnnl::stream& stream, Block& b, const dnnl::memory& input) {
  return b.conv2->run(stream, b.conv1->run(stream, input));
}

FrameEncoder::FrameEncoder(const NetworkWeights& w, int height, int width, PlanContext& context)
    : height_(height), width_(width) {
  // Built in the order run() runs them, each buffer released once what reads it is built, so
  // the region holds only what is alive at once (at 1920×1088 the 1/8 tensors are 130 KB a
  // channel). The pooled images are made first: run() computes all three before any block.
  ScratchArena& arena = context.arena;
  arena.make_tensor(input_, height, width, 3);
  arena.make_tensor(half_, height / 2, width / 2, 3);
  arena.make_tensor(quarter_, height / 4, width / 4, 3);
  arena.make_tensor(eighth_, height / 8, width / 8, 3);
  // conv_s8 first: the full-resolution image (25 MB at 1920×1088) is then no longer needed
  // when the 1/8 concatenation, the encoder's largest moment, is alive.
  conv_s8_ = make_block(w.conv_s8, 8, 0, nhwc_desc(height, width, 3), context);
  arena.release(input_);
  arena.release(conv_s8_.conv2->output());  // read by to_nhwc before the next block runs
  block_8_1_ = make_block(w.block_8_1, 4, 2, nhwc_desc(height / 2, width / 2, 3), context);
  arena.release(half_);
  block_8_2_ = make_block(w.block_8_2, 2, 2, nhwc_desc(height / 4, width / 4, 3), context);
  arena.release(quarter_);
  concat_8_ = make_concat(block_8_1_.conv2->output_desc(), block_8_2_.conv2->output_desc(), cat8_, context);
  arena.release(block_8_1_.conv2->output());
  arena.release(block_8_2_.conv2->output());
  block_cat_8_ = make_block(w.block_cat_8, 1, 1, cat8_.get_desc(), context);
  arena.release(cat8_);
  block_16_1_ = make_block(w.block_16_1, 2, 2, nhwc_desc(height / 8, width / 8, 3), context);
  arena.release(eighth_);
  block_8_16_ = make_block(w.block_8_16, 2, 2, block_cat_8_.conv2->output_desc(), context);
  arena.release(block_cat_8_.conv2->output());  // f8: read by to_nhwc and block_8_16
  concat_16_ = make_concat(block_16_1_.conv2->output_desc(), block_8_16_.conv2->output_desc(), cat16_, context);
  arena.release(block_16_1_.conv2->output());
  arena.release(block_8_16_.conv2->output());
  block_cat_16_ = make_block(w.block_cat_16, 1, 1, cat16_.get_desc(), context);
  arena.release(cat16_);
  arena.make_tensor(g_, height / 16, width / 16, block_cat_16_.conv2->out_channels());  // NHWC copy of the output
  arena.release(block_cat_16_.conv2->output());                                         // read by to_nhwc only
  arena.release(g_);                                                                    // read into f16, the last step
}

void FrameEncoder::run(dnnl::stream& stream, const Tensor& image, FrameFeatures& out) {
  avg_pool_2x(image, half_);
  avg_pool_2x(half_, quarter_);
  avg_pool_2x(quarter_, eighth_);
  auto half = wrap_nhwc(half_), quarter = wrap_nhwc(quarter_), eighth = wrap_nhwc(eighth_);
  auto full = dnnl::memory(nhwc_desc(image.h, image.w, 3), cpu_engine(), const_cast<float*>(image.data.data()));
  to_nhwc(stream, run_block(stream, conv_s8_, full), out.upsample_features);

  const auto& a = run_block(stream, block_8_1_, half);
  const auto& b = run_block(stream, block_8_2_, quarter);
  concat_8_->execute(stream, {{DNNL_ARG_MULTIPLE_SRC, a}, {DNNL_ARG_MULTIPLE_SRC + 1, b}, {DNNL_ARG_DST, cat8_}});
  const auto& f8 = run_block(stream, block_cat_8_, cat8_);
  to_nhwc(stream, f8, out.f8);

  const auto& c = run_block(stream, block_16_1_, eighth);
  const auto& d = run_block(stream, block_8_16_, f8);
  concat_16_->execute(stream, {{DNNL_ARG_MULTIPLE_SRC, c}, {DNNL_ARG_MULTIPLE_SRC + 1, d}, {DNNL_ARG_DST, cat16_}});
  to_nhwc(stream, run_block(stream, block_cat_16_, cat16_), g_);

  // f16 = concat[g, position]: the two channels are (y - h/2, x - w/2) at 1/16 scale.
  const int h16 = height_ / 16, w16 = width_ / 16;
  out.f16.resize(h16, w16, g_.c + 2);
  for (int y = 0; y < h16; ++y) {
    for (int x = 0; x < w16; ++x) {
      float* dst = out.f16.pixel(y, x);
      const float* src = g_.pixel(y, x);
      std::copy(src, src + g_.c, dst);
      dst[g_.c] = static_cast<float>(y) - static_cast<float>(h16) / 2.f;
      dst[g_.c + 1] = static_cast<float>(x) - static_cast<float>(w16) / 2.f;
    }
  }
}

}  // namespace neuflow::model
