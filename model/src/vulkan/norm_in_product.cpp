#include "vulkan/norm_in_product.hpp"

#include <algorithm>
#include <variant>

#include "vulkan/shaders.hpp"

namespace neuflow::model::vulkan {

std::optional<std::size_t> norm_after_product(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                              std::size_t i) {
  const auto* product = std::get_if<graph::Linear<DeviceTensor>>(&ops[i].op);
  if (!product || product->weights->out_features != kMatmulNormChannels || !tensors.whole(product->out) ||
      i + 1 >= ops.size()) {
    return std::nullopt;
  }
  const auto* norm = std::get_if<graph::LayerNorm<DeviceTensor>>(&ops[i + 1].op);
  if (!norm || norm->in.tensor != product->out.tensor || !tensors.whole(norm->in) ||
      (norm->residual && norm->residual->tensor == product->out.tensor) || norm->out.tensor == product->out.tensor) {
    return std::nullopt;
  }
  return i + 1;
}

std::optional<std::size_t> norm_after_mlp(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                          std::size_t i) {
  const auto* first = std::get_if<graph::Linear<DeviceTensor>>(&ops[i].op);
  if (!first || first->weights->out_features != kMlpHiddenChannels || !tensors.whole(first->out) ||
      i + 1 >= ops.size()) {
    return std::nullopt;
  }
  const auto* second = std::get_if<graph::Linear<DeviceTensor>>(&ops[i + 1].op);
  if (!second || second->in.tensor != first->out.tensor || !tensors.whole(second->in) ||
      second->weights->in_features != kMlpHiddenChannels || second->out.tensor == first->in.tensor) {
    return std::nullopt;
  }
  return norm_after_product(ops, tensors, i + 1);
}

void keep_product_inputs_to_norms(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                                  const graph::TensorTable& tensors, int first_op) {
  for (std::size_t i = 0; i < ops.size(); ++i) {
    auto norm = norm_after_product(ops, tensors, i);
    if (!norm) norm = norm_after_mlp(ops, tensors, i);
    if (!norm) continue;
    const auto& product = std::get<graph::Linear<DeviceTensor>>(ops[i].op);
    graph::stretch_live_range(ranges, product.in.tensor, first_op + static_cast<int>(i),
                              first_op + static_cast<int>(*norm));
  }
}

}  // namespace neuflow::model::vulkan
