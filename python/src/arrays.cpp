#include "arrays.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "neuflow/flow/limits.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::python {

namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string described(const py::array& a) {
  return "a " + std::string(py::str(a.dtype())) + " array of shape " + shape_of(a);
}

py::array as_array(const py::handle& object, const char* what, const char* expected) {
  if (!py::isinstance<py::array>(object)) {
    throw py::value_error(std::string(what) + ": expected " + expected + ", got " +
                          std::string(py::str(py::type::handle_of(object).attr("__name__"))));
  }
  return py::reinterpret_borrow<py::array>(object);
}

}  // namespace

Frame frame_from(const py::handle& object, model::ChannelOrder order, const char* what) {
  constexpr const char* expected = "a NumPy uint8 array of shape (H, W, 3) or (H, W)";
  const py::array a = as_array(object, what, expected);
  const bool colour = a.ndim() == 3 && a.shape(2) == 3;
  // By value, not identity: an unpickled array (multiprocessing) has a dtype object of its own.
  const bool bytes = a.dtype().kind() == 'u' && a.dtype().itemsize() == 1;
  if (!bytes || !(colour || a.ndim() == 2)) {
    throw py::value_error(std::string(what) + ": expected " + expected + ", got " + described(a));
  }
  const auto height = a.shape(0), width = a.shape(1);
  // Before anything is copied: a broadcast view can claim any size without the memory.
  constexpr auto largest = model::SessionLimits::max_side;
  if (height > largest || width > largest) {
    throw py::value_error(std::string(what) + ": a frame of " + shape_of(a) + " is larger than the " +
                          std::to_string(largest) + " pixels a side the network takes");
  }
  Frame f;
  f.view.width = static_cast<int>(width);
  f.view.height = static_cast<int>(height);
  f.view.order = order;
  if (colour && a.strides(2) == 1 && a.strides(1) == 3 && a.strides(0) >= 3 * width) {
    f.view.data = static_cast<const std::uint8_t*>(a.data());
    f.view.stride = a.strides(0);
    f.borrowed = true;
    f.keep = a;
    return f;
  }
  // Anything else (grey, channels reversed by a slice, Fortran order, ...) is copied as
  // interleaved triples.
  f.copy.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  const auto* base = static_cast<const std::uint8_t*>(a.data());
  for (py::ssize_t y = 0; y < height; ++y) {
    for (py::ssize_t x = 0; x < width; ++x) {
      std::uint8_t* out = &f.copy[(static_cast<std::size_t>(y) * width + x) * 3];
      const std::uint8_t* at = base + y * a.strides(0) + x * a.strides(1);
      for (int c = 0; c < 3; ++c) out[c] = colour ? at[c * a.strides(2)] : at[0];
    }
  }
  f.view.data = f.copy.data();
  f.view.stride = 3 * width;
  return f;
}

flow::FlowField field_from(const py::handle& object, const py::handle& valid, const char* what) {
  const py::array given = as_array(object, what, "a NumPy array of shape (H, W, 2)");
  if (given.ndim() != 3 || given.shape(2) != 2 || given.dtype().kind() != 'f') {
    throw py::value_error(std::string(what) + ": expected a float array of shape (H, W, 2), got " + described(given));
  }
  if (!flow::flow_size_acceptable(given.shape(1), given.shape(0))) {
    throw py::value_error(std::string(what) + ": a flow field of " + shape_of(given) +
                          " is not a size flow files take");
  }
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(given);
  if (!a) throw py::error_already_set();  // the conversion failed (out of memory)
  flow::FlowField field(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)));
  std::copy(a.data(), a.data() + field.uv.size(), field.uv.begin());
  if (!valid.is_none()) {
    const py::array m = as_array(valid, "valid", "a NumPy array of shape (H, W)");
    if (m.ndim() != 2 || m.shape(0) != a.shape(0) || m.shape(1) != a.shape(1) ||
        !(m.dtype().kind() == 'b' || m.dtype().kind() == 'i' || m.dtype().kind() == 'u')) {
      throw py::value_error("valid: expected a bool or integer array of shape (" + std::to_string(a.shape(0)) + ", " +
                            std::to_string(a.shape(1)) + "), the flow's, got " + described(m));
    }
    // As bool, so any nonzero integer is valid (a cast to uint8 would take 256 as 0).
    const auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(m);
    if (!mask) throw py::error_already_set();
    field.valid.resize(field.pixel_count());
    std::transform(mask.data(), mask.data() + field.pixel_count(), field.valid.begin(),
                   [](bool v) { return static_cast<std::uint8_t>(v ? 1 : 0); });
  }
  return field;
}

py::array_t<float> array_from(flow::FlowField&& field) {
  auto owner = std::make_unique<std::vector<float>>(std::move(field.uv));
  if (!field.valid.empty()) {
    for (std::size_t i = 0; i < field.valid.size(); ++i) {
      if (field.valid[i] == 0) (*owner)[2 * i] = (*owner)[2 * i + 1] = std::numeric_limits<float>::quiet_NaN();
    }
  }
  float* data = owner->data();
  py::capsule free_when_done(owner.get(), [](void* p) { delete static_cast<std::vector<float>*>(p); });
  static_cast<void>(owner.release());  // the capsule frees it now
  const py::ssize_t h = field.height, w = field.width;
  return py::array_t<float>(
      {h, w, py::ssize_t{2}},
      {w * 2 * py::ssize_t{sizeof(float)}, 2 * py::ssize_t{sizeof(float)}, py::ssize_t{sizeof(float)}}, data,
      free_when_done);
}

}  // namespace neuflow::python
