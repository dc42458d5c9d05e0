#pragma once
// Concatenations the Vulkan backend never writes: where only one-dispatch Winograd convolutions
// read a concatenation (one or two copies or resamples that write all of a transient tensor's
// channels), those convolutions read its parts where they lie (winograd_conv_params.h), which
// saves the concatenation's dispatch, its barrier and its bytes (the merges' inputs at 1/8, the
// upsampler's). Each part's source must then live until the last of those convolutions has run:
// the memory plan takes the ranges planned_live_ranges() gives it.
#include <cstddef>
#include <optional>
#include <vector>

#include "graph/memory_plan.hpp"
#include "graph/ops.hpp"
#include "vulkan/conv_algorithm.hpp"
#include "vulkan/device_weights.hpp"

namespace neuflow::model::vulkan {

// A convolution's input as the parts of its concatenation: resamples (a copy is one of factor 1,
// the factors powers of two) whose outputs are the input's channels in order.
struct ConvInputParts {
  graph::Resample first;
  std::optional<graph::Resample> second;
};

using graph::accesses_of;
// Whether slices name a tensor; whether an op reads or writes a tensor; a copy or a resample as
// a resample (a copy is one of factor 1), the form a concatenation's part takes.
bool mentions(const std::vector<graph::Slice>& slices, graph::TensorId tensor);
bool touches(const graph::Op<DeviceTensor>& op, graph::TensorId tensor);
std::optional<graph::Resample> as_resample(const graph::Op<DeviceTensor>& op);

struct InputInParts {
  ConvInputParts parts;
  std::vector<std::size_t> writers;  // the concatenation's ops, not recorded: the first part's, the second's
  std::vector<std::size_t> readers;  // the convolutions that read its parts
};

// Whether `conv` runs as a one-dispatch Winograd convolution, the form that reads in parts.
bool reads_input_in_parts(ConvAlgorithm conv, const graph::Conv2d<DeviceTensor>& op, const graph::TensorTable& tensors);

// The concatenation that ops[i] starts, where it is read in parts; nothing otherwise.
std::optional<InputInParts> input_in_parts_at(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                              std::size_t i, ConvAlgorithm conv);

// What the Vulkan memory plan follows: live_ranges() over the encode and flow passes, with each
// read-in-parts source tensor living until its last reader, each unstacked frame's tensor from
// its LayerNorm on (unstacked_output.hpp), each Winograd conv3's input until its step's end
// (winograd_conv_step) and each product's input until the LayerNorm it computes
// (norm_in_product.hpp).
graph::LiveRanges planned_live_ranges(const graph::TensorTable& tensors, const graph::OpList<DeviceTensor>& encode,
                                      const graph::OpList<DeviceTensor>& flow, ConvAlgorithm conv);

}  // namespace neuflow::model::vulkan
