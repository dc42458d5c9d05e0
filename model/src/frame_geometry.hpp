#pragma once
// How an input frame maps onto the network's input and how the flow maps back: either
// edge-replicated padding to multiples of 16 (centred), or a resize to a chosen model size.
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/model/image_view.hpp"
#include "neuflow/model/session_settings.hpp"
#include "tensor.hpp"

namespace neuflow::model {

struct FrameGeometry {
  int input_width = 0, input_height = 0;
  int model_width = 0, model_height = 0;
  bool resize = false;
  int pad_left = 0, pad_top = 0;  // padding mode only

  bool operator==(const FrameGeometry&) const = default;
};

// Throws std::invalid_argument when the size is below 32×32 or the model size is unusable.
FrameGeometry plan_geometry(int input_width, int input_height, const SessionOptions& options);

// Throws std::invalid_argument when the image is not of the geometry's input size or its
// row stride is short.
void check_image(const ImageView& image, const FrameGeometry& geometry);

// The frame as the network's input: [model_height, model_width, 3] in 0..1, its channels in
// `network_order` whatever order the image holds.
void prepare_input(const ImageView& image, const FrameGeometry& geometry, ChannelOrder network_order, Tensor& out);

// The network's flow [model_height, model_width, 2] as a flow field at the input's size.
flow::FlowField restore_flow(const Tensor& model_flow, const FrameGeometry& geometry);

}  // namespace neuflow::model
