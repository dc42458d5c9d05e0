#include "stages/refinement.hpp"

#include <algorithm>

#include "dnnl/context.hpp"
#include "ops/local_correlation.hpp"

namespace neuflow::model {

namespace {
constexpr float kHiddenClamp = 4.f;
}  // namespace

Refinement::Refinement(const RefineWeights& w, int h, int width, int iterations, PlanContext& context) {
  const bool repeated = iterations > 1;
  // In the arena: begin() and step() write each of them whole before anything reads it.
  context.arena.make_tensor(input_, h, width, kRefineDynamicChannels);
  context.arena.make_tensor(constant_, h, width, kRefineConstantChannels);
  // The chain is built in the order it runs (conv1_constant in begin(), the rest in every
  // step), and an iteration hands nothing to the next through the arena (the hidden state and
  // flow go through input_), so each convolution's output is released once the next one is
  // built; conv1_constant's stays for the pair, and conv1 writes its sum in that layout.
  ScratchArena& arena = context.arena;
  conv1_constant_.emplace(w.conv1_constant, ConvParams{1, 1, Activation::none}, nhwc_desc(h, width, constant_.c),
                          context);
  conv1_constant_->release_scratch(arena);
  arena.release(constant_);  // read in begin() only
  conv1_.emplace(w.conv1_dynamic, ConvParams{1, 1, Activation::leaky_relu, true, repeated},
                 nhwc_desc(h, width, input_.c), context, conv1_constant_->output_desc());
  conv1_->release_scratch(arena);
  conv2_.emplace(w.conv2, ConvParams{1, 1, Activation::leaky_relu, false, repeated}, conv1_->output_desc(), context);
  conv2_->release_scratch(arena);
  arena.release(conv1_->output());
  const ConvOp* prev = &*conv2_;
  for (std::size_t i = 0; i < layers_.size(); ++i) {
    layers_[i].emplace(w.conv_layers[i], ConvParams{1, 1, Activation::leaky_relu, false, repeated}, prev->output_desc(),
                       context);
    layers_[i]->release_scratch(arena);
    arena.release(prev->output());
    prev = &*layers_[i];
  }
  conv3_.emplace(w.conv3, ConvParams{1, 1, Activation::none, false, repeated}, prev->output_desc(), context);
  arena.make_tensor(output_, h, width, w.conv3.out_channels);  // written while conv3 runs
  conv3_->release_scratch(arena);
  arena.release(prev->output());
}

void Refinement::begin(dnnl::stream& stream, const Tensor& context) {
  copy_channels(all_channels(context), constant_, 0);
  for (std::size_t p = 0; p < constant_.pixels(); ++p)
    constant_.data[p * constant_.c + kContextChannels] = kCorrRadiusPlane;
  conv1_constant_->run(stream, wrap_nhwc(constant_));
  for (std::size_t p = 0; p < input_.pixels(); ++p) {
    std::fill_n(input_.data.data() + p * input_.c + kRefineHiddenOffset, kHiddenChannels, 0.f);
  }
  stream.wait();
}

void Refinement::step(dnnl::stream& stream, const ChannelSlice& f0, const ChannelSlice& f1, Tensor& flow) {
  local_correlation(f0, f1, flow, input_, 0);
  copy_channels(all_channels(flow), input_, kRefineFlowOffset);

  const auto& x1 = conv1_->run(stream, wrap_nhwc(input_), &conv1_constant_->output());
  const dnnl::memory* x = &conv2_->run(stream, x1);
  for (auto& layer : layers_) x = &layer->run(stream, *x);
  conv3_->run_to_nhwc(stream, *x, output_);
  stream.wait();

  const int hw = static_cast<int>(input_.pixels());
#pragma omp parallel for
  for (int p = 0; p < hw; ++p) {
    const float* o = output_.data.data() + static_cast<std::size_t>(p) * output_.c;
    float* hidden = input_.data.data() + static_cast<std::size_t>(p) * input_.c + kRefineHiddenOffset;
    for (int c = 0; c < kHiddenChannels; ++c) hidden[c] = std::clamp(o[2 + c], -kHiddenClamp, kHiddenClamp);
    flow.data[2 * p] += o[0];
    flow.data[2 * p + 1] += o[1];
  }
}

Tensor Refinement::hidden() const { return extract_channels({&input_, kRefineHiddenOffset, kHiddenChannels}); }

Tensor Refinement::delta() const { return extract_channels({&output_, 0, 2}); }

}  // namespace neuflow::model
