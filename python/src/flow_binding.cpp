// The flow files, the colour wheel and the accuracy measures, on NumPy arrays: flow is
// (H, W, 2) float32 with NaN where a pixel is invalid, the convention .npy flow files use.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <optional>

#include "arrays.hpp"
#include "bindings.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/metrics.hpp"
#include "neuflow/flow/visualize.hpp"

namespace neuflow::python {

namespace {

py::array_t<float> read(const std::filesystem::path& path) {
  flow::FlowField field;
  {
    const py::gil_scoped_release unlocked;
    field = flow::read_flow(path);
  }
  return array_from(std::move(field));
}

void write(const std::filesystem::path& path, const py::handle& flow, const py::handle& valid) {
  const flow::FlowField field = field_from(flow, valid, "flow");
  const py::gil_scoped_release unlocked;
  flow::write_flow(field, path);
}

py::array_t<std::uint8_t> to_color(const py::handle& flow, std::optional<double> max_flow, const py::handle& valid) {
  const flow::FlowField field = field_from(flow, valid, "flow");
  flow::RgbImage image = flow::visualize_flow(field, {max_flow}).image;
  py::array_t<std::uint8_t> out({py::ssize_t{image.height}, py::ssize_t{image.width}, py::ssize_t{3}});
  std::memcpy(out.mutable_data(), image.rgb.data(), image.rgb.size());
  return out;
}

flow::FlowMetrics measure(const py::handle& flow, const py::handle& gt, const py::handle& valid) {
  const flow::FlowField predicted = field_from(flow, py::none(), "flow");
  const flow::FlowField truth = field_from(gt, valid, "gt");
  if (predicted.width != truth.width || predicted.height != truth.height) {
    throw py::value_error("flow and gt differ in size: (" + std::to_string(predicted.height) + ", " +
                          std::to_string(predicted.width) + ", 2) against (" + std::to_string(truth.height) + ", " +
                          std::to_string(truth.width) + ", 2)");
  }
  return flow::compute_metrics(predicted, truth);
}

}  // namespace

void bind_flow(py::module_& m) {
  m.def("read_flow", &read, py::arg("path"),
        "Reads a flow file by its extension: .flo (Middlebury), .png (KITTI 16-bit) or .npy (H x W x 2 float32). "
        "Returns a float32 array of shape (H, W, 2); pixels the file marks invalid are NaN. Raises OSError when the "
        "file cannot be read or is malformed, ValueError for an extension that names no flow format.");
  m.def("write_flow", &write, py::arg("path"), py::arg("flow"), py::arg("valid") = py::none(),
        "Writes flow (H, W, 2) to a file by its extension (.flo, .png as KITTI 16-bit, .npy), atomically. Pixels "
        "with NaN or infinite values, or 0 in `valid` ((H, W) bool), are written as each format marks invalid "
        "pixels. KITTI PNG keeps 1/64 px and ±512 px.");
  m.def("flow_to_color", &to_color, py::arg("flow"), py::arg("max_flow") = py::none(), py::arg("valid") = py::none(),
        "The standard colour-wheel picture of flow as an RGB uint8 array of shape (H, W, 3): hue is the direction, "
        "saturation the magnitude up to max_flow px (None: the field's largest). Invalid pixels are black.");
  m.def(
      "epe",
      [](const py::handle& flow, const py::handle& gt, const py::handle& valid) {
        return measure(flow, gt, valid).epe;
      },
      py::arg("flow"), py::arg("gt"), py::arg("valid") = py::none(),
      "Mean end-point error |flow - gt| in px over the pixels where gt is finite (and `valid`, when given, is "
      "true). NaN when there is none; infinite when flow is not finite at such a pixel.");
  m.def(
      "metrics",
      [](const py::handle& flow, const py::handle& gt, const py::handle& valid) {
        const flow::FlowMetrics r = measure(flow, gt, valid);
        py::dict d;
        d["epe"] = r.epe;
        d["fl_all"] = r.fl_all;
        d["within_1px"] = r.within_1px;
        d["within_3px"] = r.within_3px;
        d["within_5px"] = r.within_5px;
        d["valid_pixels"] = r.valid_pixels;
        return d;
      },
      py::arg("flow"), py::arg("gt"), py::arg("valid") = py::none(),
      "The standard measures over the pixels epe() counts, as `neuflow eval` reports them: epe (px), fl_all (KITTI "
      "Fl: share with error > 3 px and > 5 % of |gt|), within_1px, within_3px, within_5px (shares), valid_pixels.");
}

}  // namespace neuflow::python
