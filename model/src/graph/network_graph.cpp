#include "graph/network_graph.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

#include "network_dims.hpp"
#include "neuflow/model/stage_observer.hpp"

namespace neuflow::model::graph {

namespace {

// Appends ops to one list at a time (encode, then flow) over the graph's one tensor table.
template <typename T>
class Builder {
 public:
  Builder(NetworkGraph<T>& graph, int block_rows, int tokens) : g_(graph), block_rows_(block_rows), tokens_(tokens) {}

  void into(OpList<T>& ops) { ops_ = &ops; }
  void emit(Op<T> op) {
    ops_->push_back({next_id_++, std::move(op)});
    g_.op_ids = std::max(g_.op_ids, next_id_);
  }

  TensorId tensor(std::string name, int c, int h, int w, Storage storage = Storage::transient,
                  std::optional<ConstantChannels> constant = std::nullopt) {
    return g_.tensors.add({std::move(name), c, h, w, storage, FrameRole::encoded, constant});
  }
  // A tensor of the same plane as `like`.
  TensorId like(std::string name, int c, TensorId like) {
    const TensorDesc& d = g_.tensors.at(like);
    return tensor(std::move(name), c, d.h, d.w);
  }
  Slice all(TensorId id) const { return g_.tensors.all(id); }

  void conv(const BasicConvWeights<T>& w, std::string layer, Slice in, Slice out, int stride, int pad, Activation act,
            std::optional<Slice> addend = std::nullopt) {
    emit(Conv2d<T>{&w, std::move(layer), in, out, stride, pad, act, addend});
  }
  void linear(const BasicLinearWeights<T>& w, std::string layer, Slice in, Slice out,
              Activation act = Activation::none) {
    emit(Linear<T>{&w, std::move(layer), in, out, act});
  }

  // ConvBlock: conv (k×k, stride, pad) → LeakyReLU → conv 3×3 → LeakyReLU, BatchNorms folded.
  struct ConvBlock {
    const BasicConvBlockWeights<T>* weights;
    std::string layer;
    Slice in;
    int stride, pad;
    Slice out;
  };
  void conv_block(const BasicConvBlockWeights<T>& w, const std::string& layer, Slice in, int stride, int pad,
                  Slice out) {
    conv_blocks({ConvBlock{&w, layer, in, stride, pad, out}});
  }
  // ConvBlocks of inputs independent of each other: their first convolutions next to each other,
  // then their second, so that a GPU runs each pair without a barrier between them.
  void conv_blocks(const std::vector<ConvBlock>& blocks) {
    std::vector<TensorId> mids;
    for (const ConvBlock& b : blocks) {
      mids.push_back(like(b.layer + ".conv1", b.weights->conv1.out_channels, b.out.tensor));
      conv(b.weights->conv1, b.layer + ".conv1", b.in, all(mids.back()), b.stride, b.pad, Activation::leaky_relu);
    }
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      const ConvBlock& b = blocks[i];
      conv(b.weights->conv2, b.layer + ".conv2", all(mids[i]), b.out, 1, 1, Activation::leaky_relu);
    }
  }

  // One cross-attention layer on the source in the first half of `mlp_in`, which holds both
  // frames' tokens (frame 0's rows above frame 1's): each frame's tokens attend to the other's.
  // Every op but the attention is token-wise, so it runs both frames at once. The tokens are
  // projected once into q, k and v (qkv_proj, q already scaled by 1/sqrt(192)): each frame's
  // queries meet the other frame's keys and values. The MLP's input is concat[source,
  // LayerNorm1(merged)]: the source is written into its half by whatever produces it, never
  // copied there.
  void attention_layer(const BasicAttentionLayerWeights<T>& w, const std::string& layer, TensorId mlp_in, Slice out) {
    const Slice source = all(mlp_in).channels(0, kFeatureChannels);
    const TensorId qkv = like(layer + ".qkv", 3 * kFeatureChannels, mlp_in);
    linear(w.qkv_proj, layer + ".qkv_proj", source, all(qkv));
    const TensorId message = like(layer + ".message", kFeatureChannels, mlp_in);
    emit(Attention{all(qkv).channels(0, kFeatureChannels), all(qkv).channels(kFeatureChannels, kFeatureChannels),
                   all(qkv).channels(2 * kFeatureChannels, kFeatureChannels), all(message), scores(), block_rows_,
                   true});
    const TensorId merged = like(layer + ".merge", kFeatureChannels, mlp_in);
    linear(w.merge, layer + ".merge", all(message), all(merged));
    emit(LayerNorm<T>{&w.norm1, layer + ".norm1", all(merged), all(mlp_in).channels(kFeatureChannels, kFeatureChannels),
                      std::nullopt});
    const TensorId hidden = like(layer + ".mlp.0", 2 * kFeatureChannels, mlp_in);
    linear(w.mlp0, layer + ".mlp.0", all(mlp_in), all(hidden), Activation::gelu);
    const TensorId mlp_out = like(layer + ".mlp.2", kFeatureChannels, mlp_in);
    linear(w.mlp2, layer + ".mlp.2", all(hidden), all(mlp_out));
    emit(LayerNorm<T>{&w.norm2, layer + ".norm2", all(mlp_out), out, source});
  }

  // Both frames' channels into `both`, a tensor of twice the rows: frame 0's above frame 1's.
  void stack_frames(std::array<Slice, 2> frames, Slice both) {
    const int h = g_.tensors.at(frames[0].tensor).h;
    for (int f = 0; f < 2; ++f) emit(CopyRows{frames[static_cast<std::size_t>(f)], both, 0, f * h, h});
  }
  void unstack_frames(TensorId both, std::array<Slice, 2> frames) {
    const int h = g_.tensors.at(frames[0].tensor).h;
    for (int f = 0; f < 2; ++f) emit(CopyRows{all(both), frames[static_cast<std::size_t>(f)], f * h, 0, h});
  }

  // `iterations` refinement steps of `flow` at its scale, from the pair's features and the
  // context in channels 0..63 of `constant_input` (its channel 64 is the radius plane).
  void refinement(const BasicRefineWeights<T>& w, const std::string& layer, std::string_view scale, Slice f0, Slice f1,
                  TensorId flow, TensorId constant_input, int iterations) {
    const TensorId input = like(layer + ".input", kRefineDynamicChannels, flow);
    const Slice corr = all(input).channels(0, kCorrChannels),
                hidden = all(input).channels(kRefineHiddenOffset, kHiddenChannels),
                flow_copy = all(input).channels(kRefineFlowOffset, 2);
    emit(Zero{hidden});
    emit(Copy{all(flow), flow_copy});
    // conv1's share of the inputs fixed for the pair, added at every step. After the step
    // input's first values and just before the first correlation, which does not depend on it:
    // a GPU runs the two under one barrier.
    const TensorId constant = like(layer + ".conv1.constant", kRefineHiddenWidth, flow);
    conv(w.conv1_constant, layer + ".conv1.conv", all(constant_input), all(constant), 1, 1, Activation::none);
    const TensorId x1 = like(layer + ".conv1", kRefineHiddenWidth, flow);
    const TensorId x2 = like(layer + ".conv2", w.conv2.out_channels, flow);
    std::array<TensorId, 5> layers{};
    for (std::size_t i = 0; i < layers.size(); ++i) {
      layers[i] = like(layer + ".conv_layers." + std::to_string(i), w.conv_layers[i].out_channels, flow);
    }
    const TensorId update = like(layer + ".conv3", kRefineOutputChannels, flow);
    const auto step = [&](int i) {
      emit(LocalCorrelation{f0, f1, all(flow), corr});
      conv(w.conv1_dynamic, layer + ".conv1.conv", all(input), all(x1), 1, 1, Activation::leaky_relu, all(constant));
      conv(w.conv2, layer + ".conv2.conv", all(x1), all(x2), 1, 1, Activation::leaky_relu);
      TensorId x = x2;
      for (std::size_t l = 0; l < layers.size(); ++l) {
        conv(w.conv_layers[l], layer + ".conv_layers." + std::to_string(l) + ".conv", all(x), all(layers[l]), 1, 1,
             Activation::leaky_relu);
        x = layers[l];
      }
      conv(w.conv3, layer + ".conv3", all(x), all(update), 1, 1, Activation::none);
      emit(RefineUpdate{all(update), hidden, flow_copy, all(flow)});
      const std::string it = stage::refine_iteration(scale, i);
      emit(StageEnd{it,
                    {{stage::corr_iteration(scale, i), 0, corr},
                     {it + "_hidden", 0, hidden},
                     {it + "_delta", 0, all(update).channels(0, 2)}}});
    };
    loop(iterations, step);
  }

  // Every iteration emits the same ops, so they take the same ids; without iterations the ids
  // are still taken (into a list thrown away), so no id depends on the iteration count.
  template <typename Step>
  void loop(int iterations, const Step& step) {
    const int first_id = next_id_;
    OpList<T> discarded;
    OpList<T>* ops = ops_;
    if (iterations == 0) ops_ = &discarded;
    for (int i = 0; i < std::max(iterations, 1); ++i) {
      next_id_ = first_id;
      step(i);
    }
    ops_ = ops;
  }

  // The score blocks of the attention and the matching: one tensor, reused by all of them.
  TensorId scores() {
    if (scores_ < 0) scores_ = tensor("scores", 1, block_rows_, tokens_);
    return scores_;
  }

 private:
  NetworkGraph<T>& g_;
  OpList<T>* ops_ = nullptr;
  int block_rows_, tokens_;
  int next_id_ = 0;
  TensorId scores_ = -1;
};

std::string str(std::string_view s) { return std::string(s); }

}  // namespace

template <typename T>
NetworkGraph<T> build_network_graph(const BasicNetworkWeights<T>& w, int height, int width,
                                    const Iterations& iterations, int score_block_rows) {
  NetworkGraph<T> g;
  g.height = height;
  g.width = width;
  const int h8 = height / 8, w8 = width / 8, h16 = height / 16, w16 = width / 16;
  Builder<T> b(g, score_block_rows, h16 * w16);

  const TensorId input = b.tensor("input", 3, height, width);
  const TensorId half = b.tensor("input/2", 3, height / 2, width / 2);
  const TensorId quarter = b.tensor("input/4", 3, height / 4, width / 4);
  const TensorId eighth = b.tensor("input/8", 3, h8, w8);
  // A frame's features in each role: the backbone's at 1/8 and 1/16 (its last two channels the
  // token positions), the upsampler's at 1/8.
  struct FrameTensors {
    TensorId f8, f16, up;
  };
  std::array<FrameTensors, 3> frames{};
  for (const FrameRole role : {FrameRole::encoded, FrameRole::first, FrameRole::second}) {
    const auto add = [&](const char* name, int c, int rows, int cols, std::optional<ConstantChannels> constant) {
      return g.tensors.add({name, c, rows, cols, Storage::frame, role, constant});
    };
    frames[static_cast<std::size_t>(role)] = {
        add("features_s8", kFeatureChannels, h8, w8, std::nullopt),
        add("features_s16", kFeatureChannels, h16, w16, ConstantChannels{kBackbone16Channels, 2, Fill::position_yx}),
        add("upsample_features", 128, h8, w8, std::nullopt)};
  }
  const FrameTensors& encoded = frames[static_cast<std::size_t>(FrameRole::encoded)];
  const FrameTensors& first = frames[static_cast<std::size_t>(FrameRole::first)];
  const FrameTensors& second = frames[static_cast<std::size_t>(FrameRole::second)];

  // ---- a frame's encoding --------------------------------------------------------------------
  b.into(g.encode);
  b.emit(FrameInput{b.all(input)});
  b.emit(AvgPool2x{b.all(input), b.all(half)});
  b.emit(AvgPool2x{b.all(half), b.all(quarter)});
  b.emit(AvgPool2x{b.all(quarter), b.all(eighth)});
  // The upsampler's features first: the full-size input (25 MB at 1920×1088) is then no longer
  // alive when the 1/8 concatenation, the encoding's largest moment, is.
  b.conv_block(w.conv_s8, "conv_s8", b.all(input), 8, 0, b.all(encoded.up));
  b.emit(StageEnd{str(stage::conv_s8), {}});
  const TensorId cat8 = b.tensor("backbone.cat_8", 384, h8, w8);
  b.conv_blocks({{&w.block_8_1, "backbone.block_8_1", b.all(half), 4, 2, b.all(cat8).channels(0, 256)},
                 {&w.block_8_2, "backbone.block_8_2", b.all(quarter), 2, 2, b.all(cat8).channels(256, 128)}});
  b.conv_block(w.block_cat_8, "backbone.block_cat_8", b.all(cat8), 1, 1, b.all(encoded.f8));
  b.emit(StageEnd{str(stage::backbone_s8), {}});
  const TensorId cat16 = b.tensor("backbone.cat_16", 256, h16, w16);
  b.conv_blocks({{&w.block_16_1, "backbone.block_16_1", b.all(eighth), 2, 2, b.all(cat16).channels(0, 128)},
                 {&w.block_8_16, "backbone.block_8_16", b.all(encoded.f8), 2, 2, b.all(cat16).channels(128, 128)}});
  b.conv_block(w.block_cat_16, "backbone.block_cat_16", b.all(cat16), 1, 1,
               b.all(encoded.f16).channels(0, kBackbone16Channels));
  b.emit(StageEnd{str(stage::backbone_s16), {}});

  // ---- a pair's flow -------------------------------------------------------------------------
  b.into(g.flow);
  b.emit(StageEnd{str(stage::backbone_s16),
                  {{str(stage::backbone_s16), 0, b.all(first.f16)}, {str(stage::backbone_s16), 1, b.all(second.f16)}}});
  b.emit(StageEnd{str(stage::backbone_s8),
                  {{str(stage::backbone_s8), 0, b.all(first.f8)}, {str(stage::backbone_s8), 1, b.all(second.f8)}}});
  b.emit(StageEnd{str(stage::conv_s8), {{str(stage::conv_s8), 0, b.all(first.up)}}});

  // 1/16: two cross-attention layers on both frames' tokens in one tensor (the second reads the
  // first's outputs of both frames), then the attention's BatchNorm.
  // Each layer's source lies in its MLP input's first half: the first layer's comes stacked
  // there, the second's from the first layer's last LayerNorm.
  const TensorId mlp_in0 = b.tensor("cross_attn_s16.layers.0.mlp_input", 2 * kFeatureChannels, 2 * h16, w16);
  const TensorId mlp_in1 = b.like("cross_attn_s16.layers.1.mlp_input", 2 * kFeatureChannels, mlp_in0);
  const TensorId attended = b.like("cross_attn_s16.layers.1", kFeatureChannels, mlp_in0);
  b.stack_frames({b.all(first.f16), b.all(second.f16)}, b.all(mlp_in0).channels(0, kFeatureChannels));
  b.attention_layer(w.attention[0], "cross_attn_s16.layers.0", mlp_in0, b.all(mlp_in1).channels(0, kFeatureChannels));
  b.attention_layer(w.attention[1], "cross_attn_s16.layers.1", mlp_in1, b.all(attended));
  b.emit(ChannelAffine<T>{&w.attention_norm_scale, &w.attention_norm_shift, "cross_attn_s16.norm", b.all(attended)});
  const TensorId att0 = b.tensor("cross_attn_s16.frame0", kFeatureChannels, h16, w16);
  const TensorId att1 = b.tensor("cross_attn_s16.frame1", kFeatureChannels, h16, w16);
  b.unstack_frames(attended, {b.all(att0), b.all(att1)});
  b.emit(StageEnd{str(stage::cross_attn_s16),
                  {{str(stage::cross_attn_s16), 0, b.all(att0)}, {str(stage::cross_attn_s16), 1, b.all(att1)}}});
  const auto context_of = [&](TensorId t) { return b.all(t).channels(0, kContextChannels); };
  const auto features_of = [&](TensorId t) { return b.all(t).channels(kContextChannels, kMatchingChannels); };

  // Global matching.
  const TensorId grid =
      b.tensor("matching.grid", 2, h16, w16, Storage::persistent, ConstantChannels{0, 2, Fill::grid_xy});
  const TensorId correspondence = b.tensor("matching.correspondence", 2, h16, w16);
  const TensorId flow16 = b.tensor("flow_s16", 2, h16, w16);
  b.emit(GlobalMatching{features_of(att0), features_of(att1), b.all(grid), b.all(flow16), b.scores(), correspondence,
                        score_block_rows});
  b.emit(StageEnd{str(stage::global_matching_flow), {{str(stage::global_matching_flow), 0, b.all(flow16)}}});

  // 1/16 refinement with the context relu(context of frame 0).
  const TensorId constant16 = b.tensor("refine_s16.constant_input", kRefineConstantChannels, h16, w16,
                                       Storage::persistent, ConstantChannels{kContextChannels, 1, Fill::radius_plane});
  b.emit(Resample{context_of(att0), b.all(constant16).channels(0, kContextChannels), 1, true, 1.f});
  b.refinement(w.refine_s16, "refine_s16", stage::scale_s16, features_of(att0), features_of(att1), flow16, constant16,
               iterations.s16);

  // 1/16 → 1/8: the flow, each frame's features merged with its attended ones, the context.
  const TensorId flow8 = b.tensor("flow_s8", 2, h8, w8);
  b.emit(Resample{b.all(flow16), b.all(flow8), 2, false, 2.f});
  // The two frames' feature merges and the context's, side by side step by step: a GPU runs
  // each step of the three without a barrier between them.
  std::array<TensorId, 2> merged{}, merge_in{}, merge_mid{};
  const std::array<std::pair<TensorId, TensorId>, 2> pair{{{first.f8, att0}, {second.f8, att1}}};
  for (std::size_t f = 0; f < 2; ++f) {
    const std::string at = "merge_s8.frame" + std::to_string(f);
    merge_in[f] = b.tensor(at + ".input", 2 * kMatchingChannels, h8, w8);
    merge_mid[f] = b.tensor(at + ".0", kMatchingChannels, h8, w8);
    merged[f] = b.tensor(at, kMatchingChannels, h8, w8);
  }
  const TensorId context_in = b.tensor("context_merge_s8.input", 2 * kContextChannels, h8, w8);
  const TensorId context_mid = b.tensor("context_merge_s8.0", kContextChannels, h8, w8);
  const TensorId constant8 = b.tensor("refine_s8.constant_input", kRefineConstantChannels, h8, w8, Storage::persistent,
                                      ConstantChannels{kContextChannels, 1, Fill::radius_plane});
  const Slice context8 = b.all(constant8).channels(0, kContextChannels);
  for (std::size_t f = 0; f < 2; ++f) {
    b.emit(Copy{features_of(pair[f].first), b.all(merge_in[f]).channels(0, kMatchingChannels)});
  }
  for (std::size_t f = 0; f < 2; ++f) {
    b.emit(Resample{features_of(pair[f].second), b.all(merge_in[f]).channels(kMatchingChannels, kMatchingChannels), 2,
                    false, 1.f});
  }
  b.emit(Resample{context_of(first.f8), b.all(context_in).channels(0, kContextChannels), 1, true, 1.f});
  b.emit(Resample{context_of(att0), b.all(context_in).channels(kContextChannels, kContextChannels), 2, true, 1.f});
  for (std::size_t f = 0; f < 2; ++f) {
    b.conv(w.merge_s8_0, "merge_s8.0", b.all(merge_in[f]), b.all(merge_mid[f]), 1, 1, Activation::gelu);
  }
  b.conv(w.context_merge_s8_0, "context_merge_s8.0", b.all(context_in), b.all(context_mid), 1, 1, Activation::gelu);
  for (std::size_t f = 0; f < 2; ++f) {
    b.conv(w.merge_s8_2, "merge_s8.2", b.all(merge_mid[f]), b.all(merged[f]), 1, 1, Activation::none);
  }
  b.conv(w.context_merge_s8_2, "context_merge_s8.2", b.all(context_mid), context8, 1, 1, Activation::none);
  b.emit(StageEnd{str(stage::merge_s8),
                  {{str(stage::merge_s8), 0, b.all(merged[0])},
                   {str(stage::merge_s8), 1, b.all(merged[1])},
                   {str(stage::context_merge_s8), 0, context8}}});

  // 1/8 refinement.
  b.refinement(w.refine_s8, "refine_s8", stage::scale_s8, b.all(merged[0]), b.all(merged[1]), flow8, constant8,
               iterations.s8);

  // Convex upsampling from [flow, the frame's upsampler features].
  const TensorId up_in = b.tensor("upsample_s8.input", 2 + 128, h8, w8);
  b.emit(Copy{b.all(flow8), b.all(up_in).channels(0, 2)});
  b.emit(Copy{b.all(first.up), b.all(up_in).channels(2, 128)});
  const TensorId u1 = b.tensor("upsample_s8.conv1", w.upsample_conv1.out_channels, h8, w8);
  const TensorId u2 = b.tensor("upsample_s8.conv2", w.upsample_conv2.out_channels, h8, w8);
  const TensorId mask = b.tensor("upsample_s8.conv3", kUpsampleMaskChannels, h8, w8);
  b.conv(w.upsample_conv1, "upsample_s8.conv1", b.all(up_in), b.all(u1), 1, 1, Activation::relu);
  b.conv(w.upsample_conv2, "upsample_s8.conv2", b.all(u1), b.all(u2), 1, 1, Activation::relu);
  b.conv(w.upsample_conv3, "upsample_s8.conv3", b.all(u2), b.all(mask), 1, 0, Activation::none);
  g.output = b.tensor("flow", 2, height, width);
  b.emit(ConvexUpsample{b.all(mask), b.all(flow8), b.all(g.output)});
  b.emit(Output{b.all(g.output)});
  b.emit(StageEnd{str(stage::flow), {{str(stage::flow), 0, b.all(g.output)}}});
  return g;
}

template NetworkGraph<std::vector<float>> build_network_graph(const BasicNetworkWeights<std::vector<float>>&, int, int,
                                                              const Iterations&, int);
template NetworkGraph<PackedTensor> build_network_graph(const BasicNetworkWeights<PackedTensor>&, int, int,
                                                        const Iterations&, int);

}  // namespace neuflow::model::graph
