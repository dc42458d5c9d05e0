#include "neuflow/model/network_cost.hpp"

#include "network_dims.hpp"
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
  const int rows = height / layer.scale, columns = width / layer.scale;  // the layer's output size
  const double positions = static_cast<double>(rows) * columns;
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

// A refinement's conv1 reads the context and radius channels, the same at every step, and the
// step's own: their share is computed once a pair and added at each step.
double layer_total(const LayerSpec& layer, int height, int width, const Iterations& it) {
  const int n = runs(layer, it);
  const bool refine = layer.stage == Stage::refine_s16 || layer.stage == Stage::refine_s8;
  if (!refine || !layer.name.ends_with(".conv1.conv") || n == 0) return n * layer_flops(layer, height, width);
  LayerSpec dynamic = layer, constant = layer;
  dynamic.in = kRefineDynamicChannels;
  constant.in = kRefineConstantChannels;
  return n * layer_flops(dynamic, height, width) + layer_flops(constant, height, width);
}

}  // namespace

NetworkCost network_cost(int height, int width, const Iterations& it) {
  NetworkCost c;
  int attention_layers = 0;
  int attention_dim = 0;
  for (const auto& layer : neuflow_v2_layers()) {
    stage_total(c, layer.stage) += layer_total(layer, height, width, it);
    if (layer.name.ends_with(".q_proj")) {
      ++attention_layers;
      attention_dim = layer.out;
    }
  }
  // What is not a layer: each attention layer's scores and weighted sum, for both frames,
  // and the global matching's correlation and softmax-weighted sum of coordinates.
  const int rows = height / 16, columns = width / 16;
  const double l = static_cast<double>(rows) * columns;
  c.cross_attention += attention_layers * 2 * (2 * l * l * attention_dim * 2);
  c.global_matching = 2 * l * l * kMatchingChannels + 2 * l * l * 2;
  return c;
}

}  // namespace neuflow::model
