#include "neuflow/model/network_cost.hpp"

#include "neuflow/model/architecture.hpp"
#include "weights.hpp"

namespace neuflow::model {

namespace {

double& stage_total(NetworkCost& c, Stage stage) {
  switch (stage) {
    case Stage::backbone: return c.backbone;
    case Stage::upsample_features: return c.upsample_features;
    case Stage::cross_attention: return c.cross_attention;
    case Stage::merge_s8: return c.merge_s8;
    case Stage::refine_s16: return c.refine_s16;
    case Stage::refine_s8: return c.refine_s8;
    case Stage::upsampler: return c.upsampler;
  }
  return c.backbone;
}

// Multiply-adds × 2 of one run of a convolution or linear layer; norms count as nothing.
double layer_flops(const LayerSpec& layer, int height, int width) {
  const double positions = static_cast<double>(height / layer.scale) * (width / layer.scale);
  switch (layer.kind) {
    case LayerKind::conv: return 2.0 * positions * layer.out * layer.in * layer.kernel * layer.kernel;
    case LayerKind::linear: return 2.0 * positions * layer.out * layer.in;
    case LayerKind::batch_norm:
    case LayerKind::layer_norm: return 0;
  }
  return 0;
}

int runs(const LayerSpec& layer, const Iterations& it) {
  if (layer.stage == Stage::refine_s16) return layer.runs * it.s16;
  if (layer.stage == Stage::refine_s8) return layer.runs * it.s8;
  return layer.runs;
}

}  // namespace

NetworkCost network_cost(int height, int width, const Iterations& it) {
  NetworkCost c;
  int attention_layers = 0;
  int attention_dim = 0;
  for (const auto& layer : neuflow_v2_layers()) {
    stage_total(c, layer.stage) += runs(layer, it) * layer_flops(layer, height, width);
    if (layer.name.ends_with(".q_proj")) {
      ++attention_layers;
      attention_dim = layer.out;
    }
  }
  // What is not a layer: each attention layer's scores and weighted sum, for both frames,
  // and the global matching's correlation and softmax-weighted sum of coordinates.
  const double l = static_cast<double>(height / 16) * (width / 16);
  c.cross_attention += attention_layers * 2 * (2 * l * l * attention_dim * 2);
  c.global_matching = 2 * l * l * kMatchingChannels + 2 * l * l * 2;
  return c;
}

}  // namespace neuflow::model
