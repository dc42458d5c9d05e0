// NeuFlow-V2 as Vulkan dispatches: each pass (a frame's encoding, a pair's flow) recorded
// stage by stage, with the stage names the observer, the timestamps and the benchmark print.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "network_dims.hpp"
#include "vulkan/network_recorder.hpp"
#include "vulkan/vulkan_network.hpp"

namespace neuflow::model::vulkan {

void VulkanNetwork::record_encode(Recorder& r, int slot, const FrameLayout* frame) {
  const int h = height_, w = width_;
  const View input{&input_, 0, 3, h, w}, half{&half_, 0, 3, h / 2, w / 2}, quarter{&quarter_, 0, 3, h / 4, w / 4},
      eighth{&eighth_, 0, 3, h / 8, w / 8};
  if (frame) {
    const FrameU8Params p{frame->width, frame->height, w, h, frame->pad_left, frame->pad_top, frame->swap ? 1 : 0};
    r.dispatch<Shader::frame_u8>({&r.upload(), nullptr, &input_, nullptr}, p, groups(static_cast<long>(h) * w, kLocal));
  } else {
    r.copy_raw(r.upload(), input_, static_cast<std::size_t>(3) * h * w);
  }
  r.avgpool(input, half);
  r.avgpool(half, quarter);
  r.avgpool(quarter, eighth);
  const auto& wt = *weights_;
  Slot& s = slots_[static_cast<std::size_t>(slot)];
  const auto block = [&](const DeviceBlock& b, const View& in, int stride, int pad, const View& out) {
    const View tmp{&encode_tmp_, 0, b.conv1.out_channels, out.h, out.w};
    r.conv(b.conv1, in, stride, pad, kActLeakyRelu, tmp);
    r.conv(b.conv2, tmp, 1, 1, kActLeakyRelu, out);
  };
  const View cat8{&cat8_, 0, 384, h8_, w8_}, f8{&s.f8, 0, kFeatureChannels, h8_, w8_};
  block(wt.block_8_1, half, 4, 2, cat8.channels(0, 256));
  block(wt.block_8_2, quarter, 2, 2, cat8.channels(256, 128));
  block(wt.block_cat_8, cat8, 1, 1, f8);
  r.mark(stage::backbone_s8);
  const View cat16{&cat16_, 0, 256, h16_, w16_};
  block(wt.block_16_1, eighth, 2, 2, cat16.channels(0, 128));
  block(wt.block_8_16, f8, 2, 2, cat16.channels(128, 128));
  block(wt.block_cat_16, cat16, 1, 1, View{&s.f16, 0, kBackbone16Channels, h16_, w16_});
  r.mark(stage::backbone_s16);
  block(wt.conv_s8, input, 8, 0, View{&s.up, 0, 128, h8_, w8_});
  r.mark(stage::conv_s8);
}

void VulkanNetwork::record_attention_layer(Recorder& r, const DeviceAttentionLayer& w, const Buffer& src,
                                           const Buffer& tgt, const Buffer& out) {
  const int l = tokens_;
  r.linear(w.q_proj, src, 0, q_, 0, l);  // already scaled by 1/sqrt(192)
  r.linear(w.k_proj, tgt, 0, k_, 0, l);
  r.linear(w.v_proj, tgt, 0, v_, 0, l);
  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    // scores[i][j] = q[:, r0 + i] · k[:, j]
    r.matmul(q_, k_, scores_, {n, l, kDim, r0, 1, l, 0, l, 1, 0, l, 1, -1, kActNone, 1.f});
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, &scores_, nullptr}, SoftmaxRowsParams{n, l, 0},
                                     static_cast<uint32_t>(n));
    // message[:, r0 + i] = v · scores[i]^T
    r.matmul(v_, scores_, message_, {kDim, n, l, 0, l, 1, 0, 1, l, r0, l, 1, -1, kActNone, 1.f});
  }
  r.linear(w.merge, message_, 0, attn_tmp_, 0, l);
  const auto layer_norm = [&](const DeviceLayerNorm& nw, const Buffer& x, const Buffer& dst, int dst_off,
                              const Buffer* residual) {
    const LayerNormParams p{kDim, l, 0, dst_off, residual ? 0 : -1, nw.gamma.offset, nw.beta.offset};
    r.dispatch<Shader::layer_norm>({&weights_->buffer, &x, &dst, residual}, p, groups(l, kLocal));
  };
  // mlp input = concat[src, LayerNorm1(merge(message))]
  layer_norm(w.norm1, attn_tmp_, mlp_in_, kDim * l, nullptr);
  r.copy(View{&src, 0, kDim, 1, l}, View{&mlp_in_, 0, kDim, 1, l});
  r.linear(w.mlp0, mlp_in_, 0, mlp_hidden_, 0, l, kActGelu);
  r.linear(w.mlp2, mlp_hidden_, 0, attn_tmp_, 0, l);
  layer_norm(w.norm2, attn_tmp_, out, 0, &src);
}

void VulkanNetwork::record_refinement(Recorder& r, const DeviceRefine& w, Refine& b, const View& f0, const View& f1,
                                      const View& flow, int iterations, std::string_view scale) {
  const int h = flow.h, wd = flow.w;
  const View input{&b.input, 0, kRefineDynamicChannels, h, wd};
  const View constant_out{&b.constant_out, 0, kRefineHiddenWidth, h, wd};
  r.conv(w.conv1_constant, View{&b.constant_in, 0, kRefineConstantChannels, h, wd}, 1, 1, kActNone, constant_out);
  r.zero(input.channels(kRefineHiddenOffset, kHiddenChannels));
  r.copy(flow, input.channels(kRefineFlowOffset, 2));
  const int inter = w.conv2.out_channels;
  for (int i = 0; i < iterations; ++i) {
    const LocalCorrelationParams cp{h, wd, f0.c, f0.offset(), f1.offset(), flow.offset(), 0};
    r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, &b.input, flow.buffer}, cp,
                                          groups(static_cast<long>(h) * wd, kLocal));
    const View xa{&b.xa, 0, kRefineHiddenWidth, h, wd};
    r.conv(w.conv1_dynamic, input, 1, 1, kActLeakyRelu, xa, &constant_out);
    View x{&b.xb, 0, inter, h, wd}, y{&b.xa, 0, inter, h, wd};
    r.conv(w.conv2, xa, 1, 1, kActLeakyRelu, x);
    for (const auto& layer : w.conv_layers) {
      r.conv(layer, x, 1, 1, kActLeakyRelu, y);
      std::swap(x, y);
    }
    const View out66{&b.out66, 0, kRefineOutputChannels, h, wd};
    r.conv(w.conv3, x, 1, 1, kActNone, out66);
    const RefineUpdateParams up{h * wd, input.channels(kRefineHiddenOffset, 1).offset(),
                                input.channels(kRefineFlowOffset, 1).offset(), flow.offset()};
    r.dispatch<Shader::refine_update>({&b.out66, nullptr, &b.input, flow.buffer}, up,
                                      groups(static_cast<long>(h) * wd, kLocal));
    const std::string it = stage::refine_iteration(scale, i);
    if (!r.observing()) {
      r.mark(it);  // the observer's three tensors of an iteration are read at its end
    } else {
      r.observe(stage::corr_iteration(scale, i), 0, input.channels(0, kCorrChannels));
      r.observe(it + "_hidden", 0, input.channels(kRefineHiddenOffset, kHiddenChannels));
      r.observe(it + "_delta", 0, out66.channels(0, 2));
    }
  }
}

void VulkanNetwork::record_flow(Recorder& r, int slot0, int slot1, const Iterations& iterations) {
  const Slot& s0 = slots_[static_cast<std::size_t>(slot0)];
  const Slot& s1 = slots_[static_cast<std::size_t>(slot1)];
  const auto& wt = *weights_;
  const int l = tokens_;
  r.observe(stage::backbone_s16, 0, View{&s0.f16, 0, kFeatureChannels, h16_, w16_});
  r.observe(stage::backbone_s16, 1, View{&s1.f16, 0, kFeatureChannels, h16_, w16_});
  r.observe(stage::backbone_s8, 0, View{&s0.f8, 0, kFeatureChannels, h8_, w8_});
  r.observe(stage::backbone_s8, 1, View{&s1.f8, 0, kFeatureChannels, h8_, w8_});
  r.observe(stage::conv_s8, 0, View{&s0.up, 0, 128, h8_, w8_});

  // 1/16: cross-attention (layer 1 reads layer 0's outputs of both frames), then its BatchNorm.
  record_attention_layer(r, wt.attention[0], s0.f16, s1.f16, state0_);
  record_attention_layer(r, wt.attention[0], s1.f16, s0.f16, state1_);
  record_attention_layer(r, wt.attention[1], state0_, state1_, attended_[0]);
  record_attention_layer(r, wt.attention[1], state1_, state0_, attended_[1]);
  for (const auto& a : attended_) {
    const ChannelAffineParams p{kDim, l, 0, wt.attention_norm_scale.offset, wt.attention_norm_shift.offset};
    r.dispatch<Shader::channel_affine>({&wt.buffer, nullptr, &a, nullptr}, p, groups(kDim * l, kLocal));
  }
  const View att0{&attended_[0], 0, kDim, h16_, w16_}, att1{&attended_[1], 0, kDim, h16_, w16_};
  r.observe(stage::cross_attn_s16, 0, att0);
  r.observe(stage::cross_attn_s16, 1, att1);

  // Global matching: softmax(F0 F1^T / sqrt(128)) G - G, in blocks of rows.
  const View feat0 = att0.channels(kContextChannels, kMatchingChannels),
             feat1 = att1.channels(kContextChannels, kMatchingChannels);
  const float alpha = 1.f / std::sqrt(static_cast<float>(kMatchingChannels));
  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    r.matmul(attended_[0], attended_[1], scores_,
             {n, l, kMatchingChannels, feat0.offset() + r0, 1, l, feat1.offset(), l, 1, 0, l, 1, -1, kActNone, alpha});
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, &scores_, nullptr}, SoftmaxRowsParams{n, l, 0},
                                     static_cast<uint32_t>(n));
    r.matmul(grid_, scores_, correspondence_, {2, n, l, 0, l, 1, 0, 1, l, r0, l, 1, -1, kActNone, 1.f});
  }
  const View flow16{&flow16_, 0, 2, h16_, w16_};
  r.axpby(1.f, View{&correspondence_, 0, 2, h16_, w16_}, -1.f, View{&grid_, 0, 2, h16_, w16_}, flow16);
  r.observe(stage::global_matching_flow, 0, flow16);

  // 1/16 refinement with ctx16 = relu(context of frame 0).
  r.resample(att0.channels(0, kContextChannels), View{&refine16_.constant_in, 0, kContextChannels, h16_, w16_}, 1, true,
             1.f);
  record_refinement(r, wt.refine_s16, refine16_, feat0, feat1, flow16, iterations.s16, stage::scale_s16);

  // 1/16 → 1/8.
  const View flow8{&flow8_, 0, 2, h8_, w8_};
  r.resample(flow16, flow8, 2, false, 2.f);
  const std::array<const Slot*, 2> frames{&s0, &s1};
  for (int f = 0; f < 2; ++f) {
    const View in{&feature_in_, 0, 2 * kMatchingChannels, h8_, w8_};
    r.copy(View{&frames[f]->f8, kContextChannels, kMatchingChannels, h8_, w8_}, in.channels(0, kMatchingChannels));
    r.resample(View{&attended_[f], kContextChannels, kMatchingChannels, h16_, w16_},
               in.channels(kMatchingChannels, kMatchingChannels), 2, false, 1.f);
    const View tmp{&merge_tmp_, 0, kMatchingChannels, h8_, w8_};
    r.conv(wt.merge_s8_0, in, 1, 1, kActGelu, tmp);
    r.conv(wt.merge_s8_2, tmp, 1, 1, kActNone, View{&features8_[f], 0, kMatchingChannels, h8_, w8_});
  }
  r.observe(stage::merge_s8, 0, View{&features8_[0], 0, kMatchingChannels, h8_, w8_});
  r.observe(stage::merge_s8, 1, View{&features8_[1], 0, kMatchingChannels, h8_, w8_});
  const View ctx_in{&context_in_, 0, 2 * kContextChannels, h8_, w8_};
  r.resample(View{&s0.f8, 0, kContextChannels, h8_, w8_}, ctx_in.channels(0, kContextChannels), 1, true, 1.f);
  r.resample(att0.channels(0, kContextChannels), ctx_in.channels(kContextChannels, kContextChannels), 2, true, 1.f);
  const View ctx_tmp{&context_tmp_, 0, kContextChannels, h8_, w8_};
  r.conv(wt.context_merge_s8_0, ctx_in, 1, 1, kActGelu, ctx_tmp);
  const View ctx8{&refine8_.constant_in, 0, kContextChannels, h8_, w8_};
  r.conv(wt.context_merge_s8_2, ctx_tmp, 1, 1, kActNone, ctx8);
  r.observe(stage::context_merge_s8, 0, ctx8);

  // 1/8 refinement.
  record_refinement(r, wt.refine_s8, refine8_, View{&features8_[0], 0, kMatchingChannels, h8_, w8_},
                    View{&features8_[1], 0, kMatchingChannels, h8_, w8_}, flow8, iterations.s8, stage::scale_s8);

  // Convex upsampling.
  const View up_in{&upsample_in_, 0, 130, h8_, w8_};
  r.copy(flow8, up_in.channels(0, 2));
  r.copy(View{&s0.up, 0, 128, h8_, w8_}, up_in.channels(2, 128));
  const View u1{&upsample1_, 0, 256, h8_, w8_}, u2{&upsample2_, 0, 512, h8_, w8_},
      mask{&mask_, 0, kUpsampleMaskChannels, h8_, w8_};
  r.conv(wt.upsample_conv1, up_in, 1, 1, kActRelu, u1);
  r.conv(wt.upsample_conv2, u1, 1, 1, kActRelu, u2);
  r.conv(wt.upsample_conv3, u2, 1, 0, kActNone, mask);
  r.dispatch<Shader::convex_upsample>({&mask_, &flow8_, &flow_full_, nullptr}, ConvexUpsampleParams{h8_, w8_},
                                      groups(static_cast<long>(height_) * width_, kLocal));
  r.copy_raw(flow_full_, r.readback(), static_cast<std::size_t>(2) * height_ * width_);
  r.host_barrier();
  r.mark(stage::flow);
}

}  // namespace neuflow::model::vulkan
