#include "vulkan/unstacked_output.hpp"

#include <algorithm>
#include <variant>

#include "vulkan/inputs_in_parts.hpp"

namespace neuflow::model::vulkan {

std::optional<UnstackedOutput> unstacked_output_at(const graph::OpList<DeviceTensor>& ops,
                                                   const graph::TensorTable& tensors, std::size_t i) {
  const auto* norm = std::get_if<graph::LayerNorm<DeviceTensor>>(&ops[i].op);
  if (!norm || !tensors.whole(norm->out)) return std::nullopt;
  const graph::TensorId stacked = norm->out.tensor;
  const graph::TensorDesc& desc = tensors.at(stacked);
  if (desc.storage != graph::Storage::transient || desc.constant || desc.h % 2 != 0) return std::nullopt;
  const int rows = desc.h / 2;
  UnstackedOutput found{};
  std::array<bool, 2> seen{};
  bool first = true;  // the next op to touch the stacked tensor is the first since the LayerNorm
  for (std::size_t k = i + 1; k < ops.size(); ++k) {
    if (!touches(ops[k].op, stacked)) continue;
    const auto* affine = std::get_if<graph::ChannelAffine<DeviceTensor>>(&ops[k].op);
    const bool folded = affine && first && affine->inout.tensor == stacked && tensors.whole(affine->inout);
    first = false;
    if (folded) continue;  // recorded in the LayerNorm's dispatch
    const auto* copy = std::get_if<graph::CopyRows>(&ops[k].op);
    if (!copy || copy->in.tensor != stacked || !tensors.whole(copy->in) || copy->rows != rows || copy->out_row != 0 ||
        copy->out.tensor == stacked || !tensors.whole(copy->out)) {
      return std::nullopt;
    }
    const graph::TensorDesc& to = tensors.at(copy->out.tensor);
    const int f = copy->in_row == 0 ? 0 : copy->in_row == rows ? 1 : -1;
    if (f < 0 || seen[static_cast<std::size_t>(f)] || to.h != rows || to.w != desc.w) return std::nullopt;
    seen[static_cast<std::size_t>(f)] = true;
    found.copies[static_cast<std::size_t>(f)] = k;
    found.frames[static_cast<std::size_t>(f)] = copy->out;
  }
  if (!seen[0] || !seen[1] || found.frames[0].tensor == found.frames[1].tensor) return std::nullopt;
  // The frames' tensors take their values at the LayerNorm now: nothing in between may touch
  // them, nor may the LayerNorm read them.
  const std::size_t last = std::max(found.copies[0], found.copies[1]);
  for (const graph::Slice& frame : found.frames) {
    if (mentions(accesses_of(ops[i].op).reads, frame.tensor)) return std::nullopt;
    for (std::size_t k = i + 1; k < last; ++k) {
      if (k != found.copies[0] && k != found.copies[1] && touches(ops[k].op, frame.tensor)) return std::nullopt;
    }
  }
  return found;
}

void start_unstacked_frames_early(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                                  const graph::TensorTable& tensors, int first_op) {
  for (std::size_t i = 0; i < ops.size(); ++i) {
    const auto found = unstacked_output_at(ops, tensors, i);
    if (!found) continue;
    for (std::size_t f = 0; f < 2; ++f) {
      const int written_at = first_op + static_cast<int>(found->copies[f]);
      for (graph::LiveRange& r : ranges[static_cast<std::size_t>(found->frames[f].tensor)]) {
        if (r.first <= written_at && written_at <= r.last) r.first = std::min(r.first, first_op + static_cast<int>(i));
      }
    }
  }
}

}  // namespace neuflow::model::vulkan
