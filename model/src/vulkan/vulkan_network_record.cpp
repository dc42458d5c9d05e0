// The network graph's passes as Vulkan commands, and the memory its tensors live in: transient
// tensors in the regions of the graph's memory plan, persistent ones and each slot's frame
// tensors in buffers of their own, constant channels filled once.
#include <algorithm>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "graph/network_graph.hpp"
#include "vulkan/inputs_in_parts.hpp"
#include "vulkan/network_recorder.hpp"
#include "vulkan/norm_in_product.hpp"
#include "vulkan/one_shot_commands.hpp"
#include "vulkan/ops/record_op.hpp"
#include "vulkan/ops/winograd.hpp"
#include "vulkan/unstacked_output.hpp"
#include "vulkan/vulkan_network.hpp"

namespace neuflow::model::vulkan {

namespace {

// Ops recorded as part of another's dispatch, which saves a dispatch and a barrier each:
// - a scale's first step input values (its hidden state zeroed, the flow copied into it), with its
//   first correlation, where no op between them touches the step input or the flow;
// - a refinement step's update, with the next step's correlation where only stage ends lie
//   between them (unobserved, a stage end reads nothing: nothing else touches the flow, the
//   update or the step input there); an observed pass keeps them apart, its observer reading
//   each step's hidden state as the step ends. A step's device time then includes the update of
//   the step before;
// - with that, the step's conv3 as well, where the network runs it as a one-dispatch Winograd
//   convolution, it directly precedes the update, and nothing else reads its output: conv3
//   computes only the hidden state, into the next step input, and the correlation's workgroups
//   compute its delta themselves (winograd_conv_step), so conv3's output is never written; a
//   scale's last update likewise, with its resample (winograd_conv_step_end);
// - a folded BatchNorm (ChannelAffine) on a LayerNorm's output, in that LayerNorm's dispatch,
//   where no op between them touches the tensor;
// - the frame's pyramid: three poolings in a chain, of an input whose sides are multiples of 8,
//   and with them the 8-bit frame's conversion into that input where the pyramid follows it;
// - a scale's last update, with the resample (or copy) of its new flow that follows it where only
//   stage ends lie between them (the next scale's flow, the upsampler's input);
// - both parts of a concatenation (a copy or a resample, then a resample into the channels after
//   it), in the second's dispatch, where no op between them touches the output or changes the
//   first part's input;
// - before all of these: a concatenation (one or two copies or resamples writing all of a
//   transient tensor's channels) that only one-dispatch Winograd convolutions read, not
//   recorded at all: they read its parts where they lie (ConvInputParts), where nothing writes
//   the parts' memory until the last of them has run;
// - likewise the cross-attention's stacked output (both frames' tokens in one tensor), where only
//   the copies that unstack it read it: its LayerNorm writes each frame's tokens where those
//   copies would put them (UnstackedOutput);
// - the convex upsampling, as the epilogue of the 1×1 convolution just before it that computes
//   its mask (unobserved, nothing else reading the mask): the mask is never written;
// - a LayerNorm (with its folded BatchNorm and unstacked output, as above), as the epilogue of
//   the matrix product just before it whose output it normalizes and nothing else reads
//   (norm_in_product.hpp): the product's output is never written; in fp16, of an MLP's two
//   products (the hidden layer in workgroup memory, never written either).
struct Fusions {
  std::vector<bool> absorbed;
  std::vector<std::optional<ConvInputParts>> conv_parts;                       // of a convolution
  std::vector<const graph::RefineUpdate*> update_first;                        // of a correlation
  std::vector<const graph::Conv2d<DeviceTensor>*> conv3_beside;                // of a correlation
  std::vector<const graph::Conv2d<DeviceTensor>*> conv3_before_end;            // of a RefineUpdate
  std::vector<std::pair<const graph::Zero*, const graph::Copy*>> start_first;  // of a correlation
  std::vector<const graph::ChannelAffine<DeviceTensor>*> affine_after;         // of a LayerNorm
  std::vector<std::optional<UnstackedOutput>> unstacked;                       // of a LayerNorm
  std::vector<const graph::ConvexUpsample*> convex_after;                      // of a Conv2d
  std::vector<bool> pyramid;                                                   // starts here
  std::vector<std::optional<graph::Resample>> concat_first;                    // of a resample
  std::vector<std::optional<graph::Resample>> resample_after;                  // of a RefineUpdate
  // Of a Linear: its LayerNorm's index, i + 1, or i + 2 where ops[i + 1] is the MLP's second layer.
  std::vector<std::optional<std::size_t>> norm_after;
};

// The resample after ops[i] that writes the channels right after its output's, with nothing
// between them touching that tensor or writing ops[i]'s input.
std::optional<std::size_t> concat_second(const graph::OpList<DeviceTensor>& ops, std::size_t i,
                                         const graph::Resample& first) {
  for (std::size_t j = i + 1; j < ops.size(); ++j) {
    const graph::Accesses a = accesses_of(ops[j].op);
    if (mentions(a.writes, first.in.tensor)) return std::nullopt;
    if (!mentions(a.reads, first.out.tensor) && !mentions(a.writes, first.out.tensor)) continue;
    const auto* second = std::get_if<graph::Resample>(&ops[j].op);
    const bool follows = second && second->out.tensor == first.out.tensor &&
                         second->out.channel == first.out.channel + first.out.c &&
                         second->in.tensor != first.out.tensor;
    return follows ? std::optional(j) : std::nullopt;
  }
  return std::nullopt;
}

// Whether the memory plan lays `kept` over any of `others`.
bool overlaps(Recorder& r, const graph::Slice& kept, const std::vector<graph::Slice>& others) {
  const View a = r.view(kept);
  return std::any_of(others.begin(), others.end(), [&](const graph::Slice& other) {
    const View b = r.view(other);
    return a.buffer == b.buffer && a.offset() < b.offset() + b.count() && b.offset() < a.offset() + a.count();
  });
}

// The concatenation that ops[i] starts, where the convolutions that read it can read its parts
// in place (inputs_in_parts.hpp): marks its ops absorbed and gives those convolutions the parts.
// The memory plan keeps the parts' sources apart from what those ops write; checked here all the
// same, as the cost of a wrong plan would be a wrong flow.
void find_input_in_parts(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors, std::size_t i,
                         Recorder& r, Fusions& f) {
  const auto found = input_in_parts_at(ops, tensors, i, r.conv_algorithm());
  if (!found) return;
  for (std::size_t p = 0; p < found->writers.size(); ++p) {
    const graph::Slice& source = (p == 0 ? found->parts.first : *found->parts.second).in;
    for (std::size_t m = found->writers[p] + 1; m <= found->readers.back(); ++m) {
      if (std::find(found->writers.begin(), found->writers.end(), m) != found->writers.end()) continue;
      if (overlaps(r, source, accesses_of(ops[m].op).writes)) {
        throw std::logic_error("the Vulkan memory plan overlaps a concatenation's part with what " +
                               graph::describe(ops[m].op) + " writes before the part is read");
      }
    }
  }
  for (const std::size_t w : found->writers) f.absorbed[w] = true;
  for (const std::size_t reader : found->readers) f.conv_parts[reader] = found->parts;
}

// The stacked tensor that the LayerNorm ops[i] writes, where it writes each frame's tokens apart:
// marks the copies that unstack it absorbed. As for the concatenations, the memory plan keeps the
// frames' tensors apart from what the LayerNorm reads, and this checks it.
void find_unstacked_output(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors, std::size_t i,
                           Recorder& r, Fusions& f) {
  const auto found = unstacked_output_at(ops, tensors, i);
  if (!found) return;
  for (const graph::Slice& frame : found->frames) {
    if (overlaps(r, frame, accesses_of(ops[i].op).reads)) {
      throw std::logic_error("the Vulkan memory plan overlaps " + tensors.at(frame.tensor).name + " with what " +
                             graph::describe(ops[i].op) + " reads");
    }
  }
  for (const std::size_t copy : found->copies) f.absorbed[copy] = true;
  f.unstacked[i] = found;
}

// The step input's first values before a scale's first correlation ops[i]: the zeroed hidden
// state and the flow's copy (their indices), where no other op since touches the step input or
// the flow.
std::optional<std::pair<std::size_t, std::size_t>> step_start_before(const graph::OpList<DeviceTensor>& ops,
                                                                     std::size_t i, const graph::LocalCorrelation& corr,
                                                                     const Fusions& f) {
  std::optional<std::size_t> zero, copy;
  for (std::size_t k = i; k-- > 0 && !(zero && copy);) {
    if (!touches(ops[k].op, corr.out.tensor) && !touches(ops[k].op, corr.flow.tensor)) continue;
    const auto* z = std::get_if<graph::Zero>(&ops[k].op);
    const auto* c = std::get_if<graph::Copy>(&ops[k].op);
    if (f.absorbed[k]) return std::nullopt;
    if (z && !zero && z->out.tensor == corr.out.tensor) {
      zero = k;
    } else if (c && !copy && c->out.tensor == corr.out.tensor && c->in.tensor == corr.flow.tensor &&
               c->in.channel == corr.flow.channel && c->in.c == 2) {
      copy = k;
    } else {
      return std::nullopt;
    }
  }
  if (!zero || !copy) return std::nullopt;
  return std::pair{*zero, *copy};
}

// The three poolings from ops[i] on, where they chain and the input's sides are multiples of 8.
std::optional<std::array<const graph::AvgPool2x*, 3>> pyramid_at(const graph::OpList<DeviceTensor>& ops,
                                                                 const graph::TensorTable& tensors, std::size_t i) {
  std::array<const graph::AvgPool2x*, 3> pools{};
  for (std::size_t l = 0; l < pools.size(); ++l) {
    pools[l] = i + l < ops.size() ? std::get_if<graph::AvgPool2x>(&ops[i + l].op) : nullptr;
    if (!pools[l] || (l > 0 && pools[l]->in.tensor != pools[l - 1]->out.tensor)) return std::nullopt;
  }
  const graph::TensorDesc& in = tensors.at(pools[0]->in.tensor);
  if (in.h % 8 != 0 || in.w % 8 != 0) return std::nullopt;
  return pools;
}

// Whether an op after ops[i] reads `tensor` on the device: the pass's Output does not (the host
// takes what the convex upsampling hands it), nor an unobserved stage end.
bool read_after(const graph::OpList<DeviceTensor>& ops, std::size_t i, graph::TensorId tensor, bool observing) {
  for (std::size_t j = i + 1; j < ops.size(); ++j) {
    if (std::holds_alternative<graph::Output>(ops[j].op)) continue;
    if (!observing && std::holds_alternative<graph::StageEnd>(ops[j].op)) continue;
    if (mentions(accesses_of(ops[j].op).reads, tensor)) return true;
  }
  return false;
}

// The refinement step's conv3 before its update ops[i], where the step's end can be computed
// beside it (record_op(conv3, update, correlation)): the one-dispatch Winograd convolution that
// writes all of the update's input just before it (stage ends aside), with a bias and nothing
// else, and whose output nothing after the correlation ops[j] reads before it is written again.
std::optional<std::size_t> conv3_before(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                        std::size_t i, std::size_t j, const graph::RefineUpdate& update,
                                        const Fusions& f, Recorder& r) {
  std::size_t k = i;
  while (k > 0 && std::holds_alternative<graph::StageEnd>(ops[k - 1].op)) --k;
  if (k == 0 || f.absorbed[k - 1] || f.conv_parts[k - 1] || f.convex_after[k - 1]) return std::nullopt;
  const auto* conv = std::get_if<graph::Conv2d<DeviceTensor>>(&ops[k - 1].op);
  if (!conv || conv->out.tensor != update.update.tensor) return std::nullopt;
  const graph::TensorDesc& out = tensors.at(conv->out.tensor);
  const bool fits = tensors.whole(conv->out) && out.c == 66 && !conv->addend && conv->act == Activation::none &&
                    conv->weights->bias.offset >= 0 && r.conv_algorithm() != ConvAlgorithm::winograd_split &&
                    takes_winograd(r.conv_algorithm(), *conv, out.h, out.w);
  if (!fits) return std::nullopt;
  // The next step's conv3 writes the tensor again before its update reads it (or, fused in turn,
  // neither writes nor reads it).
  for (std::size_t m = j + 1; m < ops.size(); ++m) {
    if (std::holds_alternative<graph::StageEnd>(ops[m].op)) continue;
    const graph::Accesses a = accesses_of(ops[m].op);
    if (mentions(a.reads, conv->out.tensor)) return std::nullopt;
    const bool rewritten = std::any_of(a.writes.begin(), a.writes.end(), [&](const graph::Slice& w) {
      return w.tensor == conv->out.tensor && tensors.whole(w);
    });
    if (rewritten && !a.partial_rows) break;
  }
  // The dispatch reads conv3's input where ops[j] runs and writes what the ops up to it write: the
  // memory plan keeps them apart (planned_live_ranges()), checked here all the same.
  for (std::size_t m = k; m <= j; ++m) {
    if (overlaps(r, conv->in, accesses_of(ops[m].op).writes)) {
      throw std::logic_error("the Vulkan memory plan overlaps " + conv->layer + "'s input with what " +
                             graph::describe(ops[m].op) + " writes before the step ends");
    }
  }
  return k - 1;
}

// The fused products' input stays apart from what their LayerNorm writes (planned_live_ranges()),
// checked here all the same.
void check_norm_output_apart(Recorder& r, const graph::Linear<DeviceTensor>& product,
                             const graph::LayerNorm<DeviceTensor>& norm,
                             const std::optional<UnstackedOutput>& unstacked) {
  const std::vector<graph::Slice> written =
      unstacked ? std::vector<graph::Slice>(unstacked->frames.begin(), unstacked->frames.end())
                : std::vector<graph::Slice>{norm.out};
  if (overlaps(r, product.in, written)) {
    throw std::logic_error("the Vulkan memory plan overlaps " + product.layer + "'s input with what " + norm.layer +
                           " writes");
  }
}

Fusions find_fusions(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors, Recorder& r) {
  Fusions f{std::vector<bool>(ops.size()),
            std::vector<std::optional<ConvInputParts>>(ops.size()),
            std::vector<const graph::RefineUpdate*>(ops.size()),
            std::vector<const graph::Conv2d<DeviceTensor>*>(ops.size()),
            std::vector<const graph::Conv2d<DeviceTensor>*>(ops.size()),
            std::vector<std::pair<const graph::Zero*, const graph::Copy*>>(ops.size()),
            std::vector<const graph::ChannelAffine<DeviceTensor>*>(ops.size()),
            std::vector<std::optional<UnstackedOutput>>(ops.size()),
            std::vector<const graph::ConvexUpsample*>(ops.size()),
            std::vector<bool>(ops.size()),
            std::vector<std::optional<graph::Resample>>(ops.size()),
            std::vector<std::optional<graph::Resample>>(ops.size()),
            std::vector<std::optional<std::size_t>>(ops.size())};
  for (std::size_t i = 0; i < ops.size(); ++i) {
    if (!f.absorbed[i]) find_input_in_parts(ops, tensors, i, r, f);
    if (!f.absorbed[i]) find_unstacked_output(ops, tensors, i, r, f);
  }
  for (std::size_t i = 0; i < ops.size(); ++i) {
    if (f.absorbed[i]) continue;
    if (const auto first = as_resample(ops[i].op); first && !f.concat_first[i]) {
      if (const auto j = concat_second(ops, i, *first); j && !f.concat_first[*j] && !f.absorbed[*j]) {
        f.absorbed[i] = true;
        f.concat_first[*j] = first;
        continue;
      }
    }
    if (pyramid_at(ops, tensors, i)) {
      f.pyramid[i] = true;
      f.absorbed[i + 1] = f.absorbed[i + 2] = true;
      continue;
    }
    if (const auto* update = std::get_if<graph::RefineUpdate>(&ops[i].op); update && !r.observing()) {
      std::size_t j = i + 1;
      while (j < ops.size() && std::holds_alternative<graph::StageEnd>(ops[j].op)) ++j;
      const auto* corr = j < ops.size() ? std::get_if<graph::LocalCorrelation>(&ops[j].op) : nullptr;
      if (corr && corr->flow.tensor == update->flow.tensor && corr->out.tensor == update->hidden.tensor &&
          corr->out.tensor == update->flow_copy.tensor) {
        f.absorbed[i] = true;
        f.update_first[j] = update;
        if (const auto k = conv3_before(ops, tensors, i, j, *update, f, r)) {
          f.absorbed[*k] = true;
          f.conv3_beside[j] = &std::get<graph::Conv2d<DeviceTensor>>(ops[*k].op);
        }
      } else {
        std::size_t last = i;  // the last op the update's dispatch takes in
        if (const auto then = j < ops.size() && !f.absorbed[j] ? as_resample(ops[j].op) : std::nullopt;
            then && then->in.tensor == update->flow.tensor && then->in.channel == update->flow.channel &&
            then->in.c == 2 && !then->relu) {
          f.absorbed[j] = true;
          f.resample_after[i] = then;
          last = j;
        }
        if (const auto k = conv3_before(ops, tensors, i, last, *update, f, r)) {
          f.absorbed[*k] = true;
          f.conv3_before_end[i] = &std::get<graph::Conv2d<DeviceTensor>>(ops[*k].op);
        }
      }
    } else if (const auto* corr = std::get_if<graph::LocalCorrelation>(&ops[i].op); corr && !f.update_first[i]) {
      if (const auto start = step_start_before(ops, i, *corr, f)) {
        f.absorbed[start->first] = f.absorbed[start->second] = true;
        f.start_first[i] = {&std::get<graph::Zero>(ops[start->first].op),
                            &std::get<graph::Copy>(ops[start->second].op)};
      }
    } else if (const auto* conv = std::get_if<graph::Conv2d<DeviceTensor>>(&ops[i].op);
               conv && conv->weights == &r.device_weights().upsample_conv3 && !r.observing() && i + 1 < ops.size()) {
      const auto* upsample = std::get_if<graph::ConvexUpsample>(&ops[i + 1].op);
      // The fused dispatch writes neither the mask nor the upsampling's output tensor, only the
      // flow the host takes: nothing on the device may read either.
      if (upsample && !f.absorbed[i + 1] && !f.conv_parts[i] && upsample->mask.tensor == conv->out.tensor &&
          upsample->mask.channel == 0 && upsample->mask.c == tensors.at(conv->out.tensor).c &&
          !read_after(ops, i + 1, conv->out.tensor, false) && !read_after(ops, i + 1, upsample->out.tensor, false)) {
        f.absorbed[i + 1] = true;
        f.convex_after[i] = upsample;
      }
    } else if (const auto* affine = std::get_if<graph::ChannelAffine<DeviceTensor>>(&ops[i].op)) {
      for (std::size_t k = i; k-- > 0;) {
        if (!touches(ops[k].op, affine->inout.tensor)) continue;
        const auto* norm = std::get_if<graph::LayerNorm<DeviceTensor>>(&ops[k].op);
        if (norm && norm->out.tensor == affine->inout.tensor && norm->out.channel == affine->inout.channel &&
            norm->out.c == affine->inout.c && !f.affine_after[k]) {
          f.absorbed[i] = true;
          f.affine_after[k] = affine;
        }
        break;
      }
    }
  }
  // After the others: the LayerNorm's folded BatchNorm and unstacked output are its own fusions.
  // In fp16 an MLP's two layers with it, else the one product before it, where no product's
  // output is read elsewhere.
  for (std::size_t i = 0; i < ops.size(); ++i) {
    if (f.absorbed[i]) continue;
    const auto unread = [&](std::size_t product, std::size_t until) {
      return !f.absorbed[until] &&
             !read_after(ops, until, std::get<graph::Linear<DeviceTensor>>(ops[product].op).out.tensor, r.observing());
    };
    auto j = r.fp16() ? norm_after_mlp(ops, tensors, i) : std::nullopt;
    if (j && !(unread(i, i + 1) && unread(i + 1, *j))) j.reset();
    if (!j) j = norm_after_product(ops, tensors, i);
    if (!j || !unread(*j - 1, *j)) continue;
    check_norm_output_apart(r, std::get<graph::Linear<DeviceTensor>>(ops[i].op),
                            std::get<graph::LayerNorm<DeviceTensor>>(ops[*j].op), f.unstacked[*j]);
    for (std::size_t k = i + 1; k <= *j; ++k) f.absorbed[k] = true;
    f.norm_after[i] = j;
  }
  return f;
}

}  // namespace

void VulkanNetwork::record(Recorder& r, const graph::OpList<DeviceTensor>& ops) {
  const Fusions f = find_fusions(ops, graph_.tensors, r);
  // One dispatch writes every level of the pyramid (and the frame's input with it): only where
  // the plan gave them buffers of their own.
  const auto own_buffers = [&](const std::array<const graph::AvgPool2x*, 3>& pools) {
    const std::array<const Buffer*, 4> buffers{r.view(pools[0]->in).buffer, r.view(pools[0]->out).buffer,
                                               r.view(pools[1]->out).buffer, r.view(pools[2]->out).buffer};
    for (std::size_t a = 0; a < buffers.size(); ++a) {
      for (std::size_t b = a + 1; b < buffers.size(); ++b) {
        if (buffers[a] == buffers[b]) return false;
      }
    }
    return true;
  };
  for (std::size_t i = 0; i < ops.size(); ++i) {
    if (f.absorbed[i]) continue;
    const auto& op = ops[i].op;
    if (f.pyramid[i]) {
      const auto pools = *pyramid_at(ops, graph_.tensors, i);
      if (own_buffers(pools)) {
        record_op(r, pools);
      } else {
        for (const auto* pool : pools) record_op(r, *pool);
      }
    } else if (const auto* frame = std::get_if<graph::FrameInput>(&op);
               frame && r.frame_layout() && i + 1 < ops.size() && f.pyramid[i + 1]) {
      // An 8-bit frame converted and pooled in one dispatch (frame_pyramid).
      const auto pools = *pyramid_at(ops, graph_.tensors, i + 1);
      if (pools[0]->in.tensor == frame->out.tensor && own_buffers(pools)) {
        record_op(r, *frame, pools);
        ++i;  // the pyramid's first pooling; the other two are absorbed
      } else {
        record_op(r, *frame);
      }
    } else if (f.conv3_beside[i]) {
      record_op(r, *f.conv3_beside[i], *f.update_first[i], std::get<graph::LocalCorrelation>(op));
    } else if (f.update_first[i]) {
      record_op(r, std::get<graph::LocalCorrelation>(op), f.update_first[i]);
    } else if (f.start_first[i].first) {
      record_op(r, std::get<graph::LocalCorrelation>(op), *f.start_first[i].first, *f.start_first[i].second);
    } else if (const auto* norm = std::get_if<graph::LayerNorm<DeviceTensor>>(&op)) {
      record_op(r, *norm, f.affine_after[i], f.unstacked[i] ? &*f.unstacked[i] : nullptr);
    } else if (const auto j = f.norm_after[i]) {
      const auto& product = std::get<graph::Linear<DeviceTensor>>(op);
      const auto& normalize = std::get<graph::LayerNorm<DeviceTensor>>(ops[*j].op);
      const auto* unstacked = f.unstacked[*j] ? &*f.unstacked[*j] : nullptr;
      if (*j == i + 2) {
        record_op(r, product, std::get<graph::Linear<DeviceTensor>>(ops[i + 1].op), normalize, f.affine_after[*j],
                  unstacked);
      } else {
        record_op(r, product, normalize, f.affine_after[*j], unstacked);
      }
    } else if (f.conv3_before_end[i]) {
      record_op(r, *f.conv3_before_end[i], std::get<graph::RefineUpdate>(op),
                f.resample_after[i] ? &*f.resample_after[i] : nullptr);
    } else if (f.resample_after[i]) {
      record_op(r, std::get<graph::RefineUpdate>(op), &*f.resample_after[i]);
    } else if (f.convex_after[i]) {
      record_op(r, std::get<graph::Conv2d<DeviceTensor>>(op), *f.convex_after[i]);
    } else if (f.conv_parts[i]) {
      record_op(r, std::get<graph::Conv2d<DeviceTensor>>(op), *f.conv_parts[i]);
    } else if (f.concat_first[i]) {
      record_op(r, *f.concat_first[i], std::get<graph::Resample>(op));
    } else if (const auto* upsample = std::get_if<graph::ConvexUpsample>(&op)) {
      record_op(r, *upsample, read_after(ops, i, upsample->out.tensor, r.observing()));
    } else {
      std::visit([&](const auto& o) { record_op(r, o); }, op);
    }
  }
}

void VulkanNetwork::record_encode(Recorder& r, int slot, const FrameLayout* frame) {
  r.bind_frames({slot, -1, -1});
  r.set_frame_layout(frame);
  record(r, graph_.encode);
}

void VulkanNetwork::record_flow(Recorder& r, int slot0, int slot1, const Iterations& iterations) {
  r.bind_frames({-1, slot0, slot1});
  record(r, flow_ops(iterations));
}

const graph::OpList<DeviceTensor>& VulkanNetwork::flow_ops(const Iterations& iterations) {
  const std::pair key{iterations.s16, iterations.s8};
  if (auto it = flow_ops_.find(key); it != flow_ops_.end()) return it->second;
  auto g = graph::build_network_graph<DeviceTensor>(*weights_, height_, width_, iterations, block_rows_);
  if (g.tensors.size() != graph_.tensors.size()) {
    throw std::logic_error("the network graph's tensors depend on its iterations");
  }
  graph::check_shapes(g);
  graph::check_plan(g.tensors, plan_, planned_live_ranges(g.tensors, g.encode, g.flow, conv_));
  return flow_ops_.emplace(key, std::move(g.flow)).first->second;
}

const Buffer& VulkanNetwork::buffer_of(graph::TensorId tensor, const std::array<int, 3>& frames) const {
  const graph::TensorDesc& d = graph_.tensors.at(tensor);
  switch (d.storage) {
    case graph::Storage::transient: {
      const int region = plan_.region[static_cast<std::size_t>(tensor)];
      if (region < 0) throw std::logic_error("the network graph's " + d.name + " has no memory: no pass uses it");
      return regions_[static_cast<std::size_t>(region)];
    }
    case graph::Storage::persistent: return persistent_.at(tensor);
    case graph::Storage::frame: {
      const int slot = frames[static_cast<std::size_t>(d.role)];
      if (slot < 0) throw std::logic_error("the network graph's " + d.name + " of a frame its pass does not bind");
      return frames_[static_cast<std::size_t>(slot)].at(d.name);
    }
  }
  throw std::logic_error("a tensor of an unknown storage");
}

void VulkanNetwork::allocate_tensors() {
  const std::size_t hw = static_cast<std::size_t>(height_) * width_;
  using M = VulkanDevice::Memory;
  const std::string size = " at " + std::to_string(width_) + "x" + std::to_string(height_);
  const auto make = [&](std::size_t values, const std::string& what, M memory = M::device) {
    return device_.create_buffer(values * elem_, memory, what + size);
  };
  // The largest range the passes zero, and the largest tensor an observer reads back.
  std::size_t zeroed = 1, observed = 1;
  for (const auto* ops : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *ops) {
      if (const auto* z = std::get_if<graph::Zero>(&node.op)) {
        zeroed = std::max(zeroed, static_cast<std::size_t>(z->out.c) * graph_.tensors.at(z->out.tensor).plane());
      } else if (const auto* s = std::get_if<graph::StageEnd>(&node.op)) {
        for (const auto& o : s->observed) {
          observed =
              std::max(observed, static_cast<std::size_t>(o.tensor.c) * graph_.tensors.at(o.tensor.tensor).plane());
        }
      }
    }
  }
  dummy_ = make(4, "a placeholder binding");
  std::size_t points = 1, products = 1;  // fp32 values
  for (const auto* ops : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *ops) {
      const auto* conv = std::get_if<graph::Conv2d<DeviceTensor>>(&node.op);
      if (!conv) continue;
      const graph::TensorDesc& out = graph_.tensors.at(conv->out.tensor);
      if (conv_ != ConvAlgorithm::winograd_split || !takes_winograd(conv_, *conv, out.h, out.w)) continue;
      const std::size_t tiles = static_cast<std::size_t>(winograd_tiles(out.w)) * winograd_tiles(out.h);
      points = std::max(points, 36 * static_cast<std::size_t>(conv->in.c) * tiles);
      products = std::max(products, 36 * static_cast<std::size_t>(conv->out.c) * tiles);
    }
  }
  winograd_points_ = device_.create_buffer(points * sizeof(float), M::device, "the Winograd tiles" + size);
  winograd_products_ = device_.create_buffer(products * sizeof(float), M::device, "the Winograd products" + size);
  zeros_ = make(zeroed, "zeros");
  for (std::size_t e = 0; e < ring_.size(); ++e) {
    ring_[e].upload = make(3 * hw, "the frame upload", M::upload);
    ring_[e].flow = device_.create_buffer(2 * hw * sizeof(float), M::readback, "the flow's read-back buffer" + size);
  }
  observed_ = make(observed, "the observer's read-back buffer", M::readback);
  for (std::size_t r = 0; r < plan_.region_size.size(); ++r) {
    regions_.push_back(make(plan_.region_size[r], "the network's memory region " + std::to_string(r)));
  }
  for (std::size_t t = 0; t < graph_.tensors.size(); ++t) {
    const graph::TensorDesc& d = graph_.tensors.at(static_cast<graph::TensorId>(t));
    if (d.storage == graph::Storage::persistent) {
      persistent_.emplace(static_cast<graph::TensorId>(t), make(d.count(), d.name));
    } else if (d.storage == graph::Storage::frame && d.role == graph::FrameRole::encoded) {
      for (std::size_t s = 0; s < frames_.size(); ++s) {
        frames_[s].emplace(d.name, make(d.count(), d.name + " of frame slot " + std::to_string(s)));
      }
    }
  }
}

// The channels no pass writes (the token positions of every slot's 1/16 features, the
// matching grid, the radius planes), and the zeros.
void VulkanNetwork::initialise_constants() {
  std::vector<float> values;
  std::vector<std::pair<const Buffer*, VkBufferCopy>> copies;
  const VkDeviceSize e = elem_;
  for (std::size_t t = 0; t < graph_.tensors.size(); ++t) {
    const graph::TensorDesc& d = graph_.tensors.at(static_cast<graph::TensorId>(t));
    if (!d.constant || (d.storage == graph::Storage::frame && d.role != graph::FrameRole::encoded)) continue;
    const std::vector<float> v = graph::constant_values(d);
    const VkBufferCopy region{values.size() * e, static_cast<VkDeviceSize>(d.constant->first) * d.plane() * e,
                              v.size() * e};
    values.insert(values.end(), v.begin(), v.end());
    if (d.storage == graph::Storage::persistent) {
      copies.emplace_back(&persistent_.at(static_cast<graph::TensorId>(t)), region);
    } else {
      for (const auto& slot : frames_) copies.emplace_back(&slot.at(d.name), region);
    }
  }
  Buffer staging =
      device_.create_buffer(std::max<std::size_t>(values.size(), 1) * elem_, VulkanDevice::Memory::upload, "constants");
  store(values.data(), values.size(), staging.mapped());
  OneShotCommands commands(device_);
  VkCommandBuffer cb = commands.buffer();
  for (const auto& [buffer, region] : copies) vkCmdCopyBuffer(cb, staging.handle(), buffer->handle(), 1, &region);
  vkCmdFillBuffer(cb, zeros_.handle(), 0, VK_WHOLE_SIZE, 0);
  commands.run();
}

}  // namespace neuflow::model::vulkan
