#pragma once
// NumPy arrays in and out of the core's types: frames as ImageView (borrowed where the array's
// layout allows), flow fields as (H, W, 2) float32 arrays with NaN where a pixel is invalid.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <vector>

#include "neuflow/flow/flow_field.hpp"
#include "neuflow/model/image_view.hpp"

namespace neuflow::python {

namespace py = pybind11;

// A frame for the session: `view` reads the array itself where its pixels are interleaved
// 8-bit triples (rows may be strided, as a crop's are), else a copy kept in `copy`. `keep`
// holds the array while the view reads it.
struct Frame {
  Frame() = default;
  Frame(Frame&&) = default;  // `copy`'s buffer moves with it, so `view` stays valid
  Frame& operator=(Frame&&) = default;
  Frame(const Frame&) = delete;  // a copy's view would read the original's buffer
  Frame& operator=(const Frame&) = delete;
  ~Frame() = default;

  model::ImageView view;
  bool borrowed = false;
  py::object keep;
  std::vector<std::uint8_t> copy;
};

// `what` names the argument in the ValueError an unusable array raises. A (H, W) array is a
// grey frame, copied into three equal channels. Needs the GIL.
Frame frame_from(const py::handle& array, model::ChannelOrder order, const char* what);

// (H, W, 2) float32 (any real dtype is converted) into a field; NaN or infinite values make a
// pixel invalid, as do zeros in `valid` ((H, W) of bool or integers) when it is given.
flow::FlowField field_from(const py::handle& array, const py::handle& valid, const char* what);

// The field as (H, W, 2) float32, taking over its buffer (no copy); invalid pixels NaN.
py::array_t<float> array_from(flow::FlowField&& field);

}  // namespace neuflow::python
