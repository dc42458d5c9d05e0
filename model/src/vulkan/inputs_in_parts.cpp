#include "vulkan/inputs_in_parts.hpp"

#include <algorithm>
#include <variant>

#include "vulkan/norm_in_product.hpp"
#include "vulkan/ops/winograd.hpp"
#include "vulkan/unstacked_output.hpp"

namespace neuflow::model::vulkan {

bool mentions(const std::vector<graph::Slice>& slices, graph::TensorId tensor) {
  return std::any_of(slices.begin(), slices.end(), [&](const graph::Slice& s) { return s.tensor == tensor; });
}

bool touches(const graph::Op<DeviceTensor>& op, graph::TensorId tensor) {
  const graph::Accesses a = accesses_of(op);
  return mentions(a.reads, tensor) || mentions(a.writes, tensor);
}

std::optional<graph::Resample> as_resample(const graph::Op<DeviceTensor>& op) {
  if (const auto* resample = std::get_if<graph::Resample>(&op)) return *resample;
  if (const auto* copy = std::get_if<graph::Copy>(&op)) return graph::Resample{copy->in, copy->out, 1, false, 1.f};
  return std::nullopt;
}

namespace {

bool power_of_two(int factor) { return factor > 0 && (factor & (factor - 1)) == 0; }

}  // namespace

bool reads_input_in_parts(ConvAlgorithm conv, const graph::Conv2d<DeviceTensor>& op,
                          const graph::TensorTable& tensors) {
  const graph::TensorDesc& out = tensors.at(op.out.tensor);
  return conv == ConvAlgorithm::winograd_fused && takes_winograd(conv, op, out.h, out.w);
}

std::optional<InputInParts> input_in_parts_at(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                              std::size_t i, ConvAlgorithm conv) {
  const auto first = as_resample(ops[i].op);
  if (!first || first->out.channel != 0) return std::nullopt;
  const graph::TensorId x = first->out.tensor;
  const graph::TensorDesc& desc = tensors.at(x);
  if (desc.storage != graph::Storage::transient || desc.constant) return std::nullopt;
  InputInParts found{{*first, std::nullopt}, {i}, {}};
  std::size_t k = i + 1;
  if (first->out.c < desc.c) {  // the second part: the next op that touches x
    for (; k < ops.size(); ++k) {
      const graph::Accesses a = accesses_of(ops[k].op);
      if (mentions(a.reads, x) || mentions(a.writes, x)) break;
    }
    const auto second = k < ops.size() ? as_resample(ops[k].op) : std::nullopt;
    if (!second || second->out.tensor != x || second->out.channel != first->out.c ||
        first->out.c + second->out.c != desc.c) {
      return std::nullopt;
    }
    found.parts.second = second;
    found.writers.push_back(k++);
  }
  for (const auto& part : {std::optional(found.parts.first), found.parts.second}) {
    if (part && (!power_of_two(part->factor) || part->in.tensor == x)) return std::nullopt;
  }
  // The readers, up to the next op that writes all of x without reading it (a new live range);
  // no other op may write x, as its channels are never written here.
  for (; k < ops.size(); ++k) {
    const graph::Accesses a = accesses_of(ops[k].op);
    if (!mentions(a.reads, x)) {
      if (!mentions(a.writes, x)) continue;
      const bool whole = !a.partial_rows && std::any_of(a.writes.begin(), a.writes.end(), [&](const graph::Slice& w) {
        return w.tensor == x && tensors.whole(w);
      });
      if (whole) break;
      return std::nullopt;
    }
    const auto* c = std::get_if<graph::Conv2d<DeviceTensor>>(&ops[k].op);
    if (!c || c->in.tensor != x || c->in.channel != 0 || c->in.c != desc.c || mentions(a.writes, x) ||
        (c->addend && c->addend->tensor == x) || !reads_input_in_parts(conv, *c, tensors)) {
      return std::nullopt;
    }
    found.readers.push_back(k);
  }
  if (found.readers.empty()) return std::nullopt;
  // Nothing may write a part's source from where the part was read to the last reader.
  for (std::size_t p = 0; p < found.writers.size(); ++p) {
    const graph::TensorId source = (p == 0 ? found.parts.first : *found.parts.second).in.tensor;
    for (std::size_t m = found.writers[p] + 1; m <= found.readers.back(); ++m) {
      if (mentions(accesses_of(ops[m].op).writes, source)) return std::nullopt;
    }
  }
  return found;
}

namespace {

// `ranges` with each read-in-parts source of `ops` (which start at op index `first_op`) living
// until its last reader.
void extend_live_ranges(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                        const graph::TensorTable& tensors, int first_op, ConvAlgorithm conv) {
  for (std::size_t i = 0; i < ops.size(); ++i) {
    const auto found = input_in_parts_at(ops, tensors, i, conv);
    if (!found) continue;
    const int last = first_op + static_cast<int>(found->readers.back());
    for (std::size_t p = 0; p < found->writers.size(); ++p) {
      const graph::Resample& part = p == 0 ? found->parts.first : *found->parts.second;
      graph::stretch_live_range(ranges, part.in.tensor, first_op + static_cast<int>(found->writers[p]), last);
    }
  }
}

// `ranges` with the input of each refinement step's conv3 that a Winograd layer computes living
// until the end of its step: the dispatch that computes conv3 beside the step's end
// (winograd_conv_step, winograd_conv_step_end) reads it where the update, or the correlation or
// resample after it, runs, and writes what those write (the next scale's flow) there.
void keep_conv3_inputs_to_step_ends(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                                    const graph::TensorTable& tensors, int first_op, ConvAlgorithm conv) {
  const auto after_stage_ends = [&](std::size_t j) {
    while (j < ops.size() && std::holds_alternative<graph::StageEnd>(ops[j].op)) ++j;
    return j;
  };
  for (std::size_t i = 0; i < ops.size(); ++i) {
    const auto* update = std::get_if<graph::RefineUpdate>(&ops[i].op);
    if (!update) continue;
    std::size_t k = i;
    while (k > 0 && std::holds_alternative<graph::StageEnd>(ops[k - 1].op)) --k;
    const auto* conv3 = k > 0 ? std::get_if<graph::Conv2d<DeviceTensor>>(&ops[k - 1].op) : nullptr;
    if (!conv3 || conv3->out.tensor != update->update.tensor) continue;
    const graph::TensorDesc& out = tensors.at(conv3->out.tensor);
    if (!takes_winograd(conv, *conv3, out.h, out.w)) continue;
    const std::size_t j = after_stage_ends(i + 1);
    const bool joined = j < ops.size() && (std::holds_alternative<graph::LocalCorrelation>(ops[j].op) ||
                                           as_resample(ops[j].op).has_value());
    graph::stretch_live_range(ranges, conv3->in.tensor, first_op + static_cast<int>(k - 1),
                              first_op + static_cast<int>(joined ? j : i));
  }
}

}  // namespace

graph::LiveRanges planned_live_ranges(const graph::TensorTable& tensors, const graph::OpList<DeviceTensor>& encode,
                                      const graph::OpList<DeviceTensor>& flow, ConvAlgorithm conv) {
  graph::LiveRanges ranges = graph::live_ranges<DeviceTensor>(tensors, {&encode, &flow});
  extend_live_ranges(ranges, encode, tensors, 0, conv);
  extend_live_ranges(ranges, flow, tensors, static_cast<int>(encode.size()), conv);
  start_unstacked_frames_early(ranges, encode, tensors, 0);
  start_unstacked_frames_early(ranges, flow, tensors, static_cast<int>(encode.size()));
  keep_conv3_inputs_to_step_ends(ranges, flow, tensors, static_cast<int>(encode.size()), conv);
  keep_product_inputs_to_norms(ranges, encode, tensors, 0);
  keep_product_inputs_to_norms(ranges, flow, tensors, static_cast<int>(encode.size()));
  return ranges;
}

}  // namespace neuflow::model::vulkan
