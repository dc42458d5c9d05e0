// neuflow.Model and neuflow.Session: a loaded checkpoint with the options its sessions run
// with, and per-stream sessions over it. Option names, defaults, limits and help texts are the
// session settings' (session_settings.hpp, session_option_docs.hpp), as the command line's, the
// element's and the daemon's are; Python spells their dashes as underscores.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "neuflow/model/architecture.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/session_option_docs.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::python {

namespace {

// The option's name as a Python keyword: "iters-s16" → "iters_s16".
std::string keyword(const model::OptionDoc& doc) {
  std::string name(doc.name);
  for (char& c : name) c = c == '-' ? '_' : c;
  return name;
}

// "keyword: help" for the docstrings.
std::string documented(const model::OptionDoc& doc) {
  return "    " + keyword(doc) + ": " + std::string(doc.help) + ".\n";
}

void check(const std::optional<std::string>& problem, const model::OptionDoc& doc) {
  if (problem) throw py::value_error(keyword(doc) + ": " + *problem);
}

template <typename T>
T parse(std::optional<T> parsed, const std::string& given, const model::OptionDoc& doc, const char* expected) {
  if (!parsed) throw py::value_error(keyword(doc) + ": expected " + expected + ", got \"" + given + "\"");
  return *parsed;
}

// What a session does other than asked (FlowSession::fallback_warning()) as a RuntimeWarning.
// Needs the GIL.
void warn(const std::string& warning) {
  if (!warning.empty() && PyErr_WarnEx(PyExc_RuntimeWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
}

// A checkpoint loaded once per file in the process, the options its sessions share, and one
// session opened on them: it says where the network runs, and on a GPU it keeps the uploaded
// weights that every session of the model shares.
struct LoadedModel {
  std::shared_ptr<const model::FlowModel> model;
  model::SessionOptions options;
  std::unique_ptr<model::FlowSession> probe;
};

class Session {
 public:
  Session(std::shared_ptr<LoadedModel> loaded, const model::SessionOptions& options, model::ChannelOrder frame_order)
      : loaded_(std::move(loaded)),
        session_(loaded_->model, options),
        frame_order_(frame_order),
        reported_(loaded_->probe->fallback_warning()),  // the model's warning said it already
        fallback_(session_.fallback_warning()) {}

  // Warns once of a fallback the model's warning did not announce (a GPU that failed for this
  // session, at its opening or at a frame size). Needs the GIL.
  void warn_of_fallback() {
    std::string now;
    {
      const std::lock_guard lock(mutex_);
      now = fallback_;
    }
    if (now != reported_) {
      reported_ = now;
      warn(now);
    }
  }

  py::object compute(const py::handle& frame0, const py::handle& frame1) {
    const Frame a = frame_from(frame0, frame_order_, "frame0");
    const Frame b = frame_from(frame1, frame_order_, "frame1");
    flow::FlowField flow;
    {
      const py::gil_scoped_release unlocked;
      const std::lock_guard lock(mutex_);
      const Noted noted(*this);
      flow = session_.compute(a.view, b.view);
    }
    warn_of_fallback();
    return array_from(std::move(flow));
  }

  py::object push(const py::handle& frame) {
    const Frame f = frame_from(frame, frame_order_, "frame");
    std::optional<flow::FlowField> flow;
    {
      const py::gil_scoped_release unlocked;
      const std::lock_guard lock(mutex_);
      const Noted noted(*this);
      flow = session_.push(f.view);
    }
    warn_of_fallback();
    if (!flow) return py::none();
    return array_from(std::move(*flow));
  }

  void reset() {
    const py::gil_scoped_release unlocked;
    const std::lock_guard lock(mutex_);
    session_.reset();
  }

  // Seconds a compute() of these frames takes in C++ alone, the least of `runs`: what the
  // binding's overhead is measured against (bench/python_binding_overhead.py).
  double time_compute(const py::handle& frame0, const py::handle& frame1, int runs) {
    const Frame a = frame_from(frame0, frame_order_, "frame0");
    const Frame b = frame_from(frame1, frame_order_, "frame1");
    const py::gil_scoped_release unlocked;
    const std::lock_guard lock(mutex_);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < runs; ++i) {
      const auto start = std::chrono::steady_clock::now();
      const flow::FlowField flow = session_.compute(a.view, b.view);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    return best;
  }

  // Where the network runs; it can change during a call (a GPU left for the CPU), so it is read
  // under the lock, without the GIL.
  std::string device() {
    const py::gil_scoped_release unlocked;
    const std::lock_guard lock(mutex_);
    return session_.backend_description();
  }
  const model::SessionOptions& options() const { return session_.options(); }
  model::ChannelOrder frame_order() const { return frame_order_; }

 private:
  // Copies the session's fallback warning when a call ends, under the call's lock.
  struct Noted {
    explicit Noted(Session& s) : session(s) {}
    ~Noted() { session.fallback_ = session.session_.fallback_warning(); }
    Noted(const Noted&) = delete;
    Noted& operator=(const Noted&) = delete;
    Session& session;
  };

  std::shared_ptr<LoadedModel> loaded_;  // the model outlives its sessions
  model::FlowSession session_;
  model::ChannelOrder frame_order_;
  std::mutex mutex_;      // one call at a time: the GIL is not held while the network runs
  std::string reported_;  // the fallback warning last given (with the GIL)
  std::string fallback_;  // the session's, as the last call left it (under mutex_)
};

std::shared_ptr<LoadedModel> load(const std::filesystem::path& path, const std::string& backend, int device,
                                  const std::string& precision, int threads, int max_memory) {
  namespace docs = model::option_docs;
  auto loaded = std::make_shared<LoadedModel>();
  model::SessionOptions& o = loaded->options;
  o.backend = parse(model::parse_backend(backend), backend, docs::backend, "auto, cpu or vulkan");
  o.precision = parse(model::parse_precision(precision), precision, docs::precision, "fp32 or fp16");
  check(model::check_device(device), docs::device);
  check(model::check_threads(threads), docs::threads);
  check(model::check_max_memory(max_memory), docs::max_memory);
  o.device = device;
  o.threads = threads;
  o.max_memory_mb = max_memory;
  try {
    const py::gil_scoped_release unlocked;
    loaded->model = model::FlowModel::load_shared(path);
    loaded->probe = std::make_unique<model::FlowSession>(loaded->model, o);
  } catch (const model::CheckpointError& e) {
    std::error_code ec;
    if (e.kind() != model::CheckpointError::Kind::kIo || std::filesystem::exists(path, ec)) throw;
    PyErr_SetString(PyExc_FileNotFoundError, e.what());
    throw py::error_already_set();
  }
  warn(loaded->probe->fallback_warning());
  return loaded;
}

py::dict info(const LoadedModel& m) {
  py::dict d;
  d["architecture"] = "NeuFlow-V2";
  d["parameters"] = model::kNeuflowV2ParameterCount;
  d["checkpoint"] = m.model->path().string();
  d["backend"] = std::string(model::backend_name(m.probe->options().backend));
  d["device"] = m.probe->backend_description();
  d["precision"] = std::string(model::precision_name(m.options.precision));
  d["threads"] = m.options.threads;
  const std::string& warning = m.probe->fallback_warning();
  d["warning"] = warning.empty() ? py::object(py::none()) : py::object(py::str(warning));
  return d;
}

std::unique_ptr<Session> open_session(const std::shared_ptr<LoadedModel>& m, int iters_s16, int iters_s8,
                                      const std::optional<std::pair<int, int>>& model_size,
                                      const std::string& channel_order, const std::optional<std::string>& frame_order) {
  namespace docs = model::option_docs;
  model::SessionOptions o = m->options;
  check(model::check_iterations_s16(iters_s16), docs::iters_s16);
  check(model::check_iterations_s8(iters_s8), docs::iters_s8);
  o.iterations = {iters_s16, iters_s8};
  if (model_size) {
    if (const auto problem = model::check_model_size(model_size->first, model_size->second)) {
      throw py::value_error("model_size: " + *problem);
    }
    o.model_width = model_size->first;
    o.model_height = model_size->second;
  }
  o.network_order = parse(model::parse_channel_order(channel_order), channel_order, docs::channel_order, "rgb or bgr");
  model::ChannelOrder frames = o.network_order;
  if (frame_order) {
    const auto parsed = model::parse_channel_order(*frame_order);
    if (!parsed) throw py::value_error("frame_order: expected rgb or bgr, got \"" + *frame_order + "\"");
    frames = *parsed;
  }
  std::unique_ptr<Session> session;
  {
    const py::gil_scoped_release unlocked;  // a GPU session compiles and uploads
    session = std::make_unique<Session>(m, o, frames);
  }
  session->warn_of_fallback();
  return session;
}

}  // namespace

void bind_model(py::module_& m) {
  namespace docs = model::option_docs;
  const model::SessionOptions defaults;
  const model::Iterations iterations;

  py::class_<LoadedModel, std::shared_ptr<LoadedModel>>(
      m, "Model",
      ("A NeuFlow-V2 checkpoint loaded for inference, shared read-only by its sessions (and by every Model of the "
       "same file in the process).\n\n"
       "Model(path, backend='auto', device=-1, precision='fp32', threads=0, max_memory=0)\n\n"
       "    path: the checkpoint (.pth, the published format).\n" +
       documented(docs::backend) + documented(docs::device) + documented(docs::precision) + documented(docs::threads) +
       documented(docs::max_memory) +
       "\nRaises OSError for a file it cannot read, neuflow.ModelError for one that is not a NeuFlow-V2 "
       "checkpoint, ValueError for an unusable option, neuflow.BackendError when backend='vulkan' finds no "
       "usable device. With backend='auto', a GPU that fails is left for the CPU with a RuntimeWarning.")
          .c_str())
      .def(py::init(&load), py::arg("path"), py::arg("backend") = std::string(model::backend_name(defaults.backend)),
           py::arg("device") = defaults.device,
           py::arg("precision") = std::string(model::precision_name(defaults.precision)),
           py::arg("threads") = defaults.threads, py::arg("max_memory") = defaults.max_memory_mb)
      .def_property_readonly("info", &info,
                             "dict: architecture, parameters (trainable, as the paper counts them), checkpoint, "
                             "backend, device (where the network runs), precision, threads, warning (why it runs "
                             "elsewhere than asked, or None)")
      .def("session", &open_session, py::arg("iters_s16") = iterations.s16, py::arg("iters_s8") = iterations.s8,
           py::arg("model_size") = py::none(),
           py::arg("channel_order") = std::string(model::channel_order_name(defaults.network_order)),
           py::arg("frame_order") = py::none(),
           ("A session over this model: for pairs (compute) or a stream of frames (push).\n\n" +
            documented(docs::iters_s16) + documented(docs::iters_s8) +
            "    model_size: (width, height) the network runs at, multiples of 16; None: the frames' own size, "
            "edge-padded.\n" +
            documented(docs::channel_order) +
            "    frame_order: the order of the frames' channels, 'rgb' or 'bgr' (OpenCV's); None: as channel_order, "
            "so the frames are fed as they are.\n")
               .c_str())
      .def("__repr__", [](const LoadedModel& l) {
        return "neuflow.Model('" + l.model->path().string() + "', device='" + l.probe->backend_description() + "')";
      });

  py::class_<Session>(m, "Session",
                      "Computes flow with a Model (Model.session() makes one). Frames are NumPy uint8 arrays of shape "
                      "(H, W, 3) in the session's frame_order, or (H, W) grey; arrays whose pixels are interleaved "
                      "triples (C order, or rows of a crop) are read in place, others copied. Flow comes back as "
                      "float32 arrays of shape (H, W, 2): u (right) and v (down) in pixels, from the earlier frame "
                      "to the later. The GIL is released while the network runs, so sessions in other threads run "
                      "at the same time; calls on one session wait for each other.")
      .def("compute", &Session::compute, py::arg("frame0"), py::arg("frame1"),
           "The flow from frame0 to frame1 (same size). Does not touch the stream.")
      .def("push", &Session::push, py::arg("frame"),
           "Streaming: the flow from the previous frame to this one, or None for the first frame (and the first "
           "after reset() or a change of frame size). Each frame's features are computed once.")
      .def("reset", &Session::reset, "Forgets the stream: the next push() returns None.")
      .def("_time_compute", &Session::time_compute, py::arg("frame0"), py::arg("frame1"), py::arg("runs") = 3,
           "Seconds compute() takes in C++ alone, the least of `runs` (for bench/python_binding_overhead.py).")
      .def_property_readonly("device", &Session::device, "Where the network runs, e.g. 'cpu'.")
      .def_property_readonly(
          "options",
          [](const Session& s) {
            const model::SessionOptions& o = s.options();
            py::dict d;
            d["iters_s16"] = o.iterations.s16;
            d["iters_s8"] = o.iterations.s8;
            d["model_size"] =
                o.model_width == 0 ? py::object(py::none()) : py::object(py::make_tuple(o.model_width, o.model_height));
            d["channel_order"] = std::string(model::channel_order_name(o.network_order));
            d["frame_order"] = std::string(model::channel_order_name(s.frame_order()));
            return d;
          },
          "dict: the session's iters_s16, iters_s8, model_size, channel_order and frame_order.")
      .def("__repr__", [](Session& s) { return "neuflow.Session(device='" + s.device() + "')"; });

  m.def(
      "_takes_without_copy",
      [](const py::handle& frame) { return frame_from(frame, model::ChannelOrder::rgb, "frame").borrowed; },
      py::arg("frame"), "Whether a session reads this frame in place rather than copying it (for tests).");
}

}  // namespace neuflow::python
