#pragma once
// NeuFlow-V2's fixed dimensions, defined once: the architecture table, the weight packer, the
// cost model and both backends read them from here (shared/docs/neuflow-v2-network.md).

namespace neuflow::model {

// The cross-attention's tokens and the backbone's outputs at 1/8 and 1/16: context channels
// first, then the features that are matched.
inline constexpr int kFeatureChannels = 192;
inline constexpr int kContextChannels = 64;
inline constexpr int kMatchingChannels = kFeatureChannels - kContextChannels;  // 128
// The 1/16 backbone's own channels; the last two of its 192 are the token positions.
inline constexpr int kBackbone16Channels = kFeatureChannels - 2;

// The refinement: a 9×9 correlation window (radius 4), a hidden state, the flow.
inline constexpr int kCorrRadius = 4;
inline constexpr int kCorrWindow = 2 * kCorrRadius + 1;          // 9
inline constexpr int kCorrChannels = kCorrWindow * kCorrWindow;  // 81
inline constexpr int kHiddenChannels = 64;
// Its input, in the order the dynamic part of conv1 reads it: corr, hidden, flow; then the part
// fixed for a pair: context, the radius plane.
inline constexpr int kRefineDynamicChannels = kCorrChannels + kHiddenChannels + 2;  // 147
inline constexpr int kRefineHiddenOffset = kCorrChannels;                           // in the dynamic part
inline constexpr int kRefineFlowOffset = kCorrChannels + kHiddenChannels;
inline constexpr int kRefineConstantChannels = kContextChannels + 1;                           // 65
inline constexpr int kRefineInputChannels = kRefineDynamicChannels + kRefineConstantChannels;  // 212
inline constexpr int kRefineHiddenWidth = 128;                                                 // conv1's output
inline constexpr int kRefineOutputChannels = 2 + kHiddenChannels;  // conv3: flow update, hidden
inline constexpr float kCorrRadiusPlane = static_cast<float>(kCorrRadius);

// The convex upsampler: 1/8 → full size, a 3×3 neighbourhood weighted per output pixel.
inline constexpr int kUpsampleFactor = 8;
inline constexpr int kUpsampleMaskChannels = 9 * kUpsampleFactor * kUpsampleFactor;  // 576

}  // namespace neuflow::model
