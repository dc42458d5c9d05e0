#pragma once
// Each graph op as Vulkan commands, one file per op (ncnn's layer/vulkan/ habit): a new kernel
// for an op replaces that op's file, and a new op adds one file here and one in the CPU's.
#include <array>

#include "graph/ops.hpp"
#include "vulkan/device_weights.hpp"
#include "vulkan/inputs_in_parts.hpp"
#include "vulkan/network_recorder.hpp"
#include "vulkan/unstacked_output.hpp"

namespace neuflow::model::vulkan {

using Recorder = VulkanNetwork::Recorder;

void record_op(Recorder& r, const graph::FrameInput& op);
// An 8-bit frame (Recorder::frame_layout()) converted into the input and pooled three times
// (`pyramid`, of that input) in one dispatch.
void record_op(Recorder& r, const graph::FrameInput& op, const std::array<const graph::AvgPool2x*, 3>& pyramid);
void record_op(Recorder& r, const graph::AvgPool2x& op);
// Three poolings in a chain, of an input whose sides are multiples of 8, in one dispatch.
void record_op(Recorder& r, const std::array<const graph::AvgPool2x*, 3>& ops);
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& op);
// The input read where its concatenation's parts lie (inputs_in_parts.hpp), in the one-dispatch
// Winograd forms.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& op, const ConvInputParts& parts);
void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op);
// The product with the LayerNorm `norm` of its output (with `then` and `unstacked` as the
// LayerNorm takes them below) in one dispatch, the product's output never written
// (norm_in_product.hpp).
void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op, const graph::LayerNorm<DeviceTensor>& norm,
               const graph::ChannelAffine<DeviceTensor>* then, const UnstackedOutput* unstacked);
// An MLP's two layers (`first`, `second`) and the LayerNorm `norm` of its output in one dispatch
// (fp16), neither layer's output written.
void record_op(Recorder& r, const graph::Linear<DeviceTensor>& first, const graph::Linear<DeviceTensor>& second,
               const graph::LayerNorm<DeviceTensor>& norm, const graph::ChannelAffine<DeviceTensor>* then,
               const UnstackedOutput* unstacked);
void record_op(Recorder& r, const graph::Attention& op);
// `then`: a folded BatchNorm applied to the output in the same dispatch (or nullptr);
// `unstacked`: both frames' tokens written apart, where the copies that would unstack them go.
void record_op(Recorder& r, const graph::LayerNorm<DeviceTensor>& op,
               const graph::ChannelAffine<DeviceTensor>* then = nullptr, const UnstackedOutput* unstacked = nullptr);
void record_op(Recorder& r, const graph::ChannelAffine<DeviceTensor>& op);
void record_op(Recorder& r, const graph::GlobalMatching& op);
void record_op(Recorder& r, const graph::Resample& op);
// Two resamples (a copy is one of factor 1) into consecutive channel ranges of one tensor, `second`
// after `first`, in one dispatch: both parts of a concatenation.
void record_op(Recorder& r, const graph::Resample& first, const graph::Resample& second);
void record_op(Recorder& r, const graph::Copy& op);
void record_op(Recorder& r, const graph::CopyRows& op);
void record_op(Recorder& r, const graph::Zero& op);
void record_op(Recorder& r, const graph::LocalCorrelation& op);
// The correlation with the previous refinement step's update applied first, in one dispatch
// (`previous` nullptr: the correlation alone).
void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::RefineUpdate* previous);
// The correlation with the previous step's end, computed beside that step's conv3 (`conv3`, for
// the hidden state only) in one dispatch: conv3, `previous` and the correlation in one.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& previous,
               const graph::LocalCorrelation& op);
// A scale's first correlation with the step input's first values (its hidden state zeroed, the
// flow copied into it: `hidden`, `flow_copy`) in one dispatch.
void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::Zero& hidden, const graph::Copy& flow_copy);
// `then`: a resample (or copy) of the new flow into another tensor, written in the same dispatch
// (or nullptr).
void record_op(Recorder& r, const graph::RefineUpdate& op, const graph::Resample* then = nullptr);
// A scale's last step's end computed beside its conv3 (for the hidden state only) in one
// dispatch: conv3, the update and `then` (as above) in one.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& conv3, const graph::RefineUpdate& op,
               const graph::Resample* then);
// Where the update writes its resampled flow (`then`'s output; an empty view without `then`),
// checked to be the whole new flow upsampled.
View resampled_flow(Recorder& r, const graph::RefineUpdate& op, const graph::Resample* then);
// The flow into the ring entry's read-back buffer as the host takes it, and with `planar` (where
// an op other than Output reads the output tensor) into that tensor as well.
void record_op(Recorder& r, const graph::ConvexUpsample& op, bool planar = true);
// The convex upsampling as the epilogue of the 1×1 convolution that computes its mask (`mask`,
// upsample_conv3), the mask never written: the flow into the read-back buffer only.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& mask, const graph::ConvexUpsample& op);
void record_op(Recorder& r, const graph::Output& op);
void record_op(Recorder& r, const graph::StageEnd& op);

// The shaders without offsets in their parameters take whole buffers.
inline void require_whole(const View& v, const char* what) {
  if (v.offset() != 0) throw std::logic_error(std::string("the Vulkan ") + what + " needs a tensor of its own");
}

}  // namespace neuflow::model::vulkan
