// One [[stream]]: its name, its [stream.flow] settings, and the source and sinks it holds.
#include <array>
#include <map>

#include "config_read.hpp"
#include "config_values.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {
namespace {

using Need = TableReader::Need;
using SessionLimits = model::SessionLimits;

}  // namespace

FlowConfig read_flow(const TableReader& t, const std::string& stream, ReadContext& context) {
  static constexpr std::array<std::string_view, 11> keys = {"model",        "iters-s16", "iters-s8",  "model-width",
                                                            "model-height", "threads",   "behaviour", "channel-order",
                                                            "backend",      "device",    "precision"};
  static constexpr std::array<std::string_view, 2> precisions = {"fp32", "fp16"};
  static constexpr std::array<std::string_view, 3> backends = {"auto", "cpu", "vulkan"};
  static constexpr std::array<std::string_view, 3> behaviours = {"auto", "live", "every-pair"};
  static constexpr std::array<std::string_view, 2> orders = {model::channel_order_name(model::ChannelOrder::rgb),
                                                             model::channel_order_name(model::ChannelOrder::bgr)};
  t.allow_only(keys);
  FlowConfig f;
  f.where = t.where();
  if (auto model = t.string("model", Need::required)) {
    if (model->empty()) {
      t.report("model", "expected the path of a NeuFlow-V2 checkpoint (.pth), got an empty string");
    } else {
      f.model = context.need_path(PathNeed::Kind::checkpoint, *model, "model", t.position("model"));
    }
  }
  if (auto v = t.integer("iters-s16", 0, SessionLimits::max_iterations_s16)) f.iters_s16 = static_cast<int>(*v);
  if (auto v = t.integer("iters-s8", 0, SessionLimits::max_iterations_s8)) f.iters_s8 = static_cast<int>(*v);
  const auto width = t.integer("model-width", 0, SessionLimits::max_side);
  const auto height = t.integer("model-height", 0, SessionLimits::max_side);
  const auto width_problem = width ? model::check_model_side(static_cast<int>(*width)) : std::nullopt;
  const auto height_problem = height ? model::check_model_side(static_cast<int>(*height)) : std::nullopt;
  if (width_problem) {
    t.report("model-width", *width_problem);
  } else if (height_problem) {
    t.report("model-height", *height_problem);
  } else if (width && height) {
    if ((*width == 0) != (*height == 0)) {
      t.report(*width == 0 ? "model-width" : "model-height",
               "model-width and model-height go together: both 0 (the frames' own size) or both set");
    }
    f.model_width = static_cast<int>(*width);
    f.model_height = static_cast<int>(*height);
  } else if ((width && *width != 0) || (height && *height != 0)) {
    t.report(width ? "model-width" : "model-height",
             std::string("model-width and model-height go together: add ") + (width ? "model-height" : "model-width"));
  }
  if (auto v = t.integer("threads", 0, SessionLimits::max_threads)) f.threads = static_cast<int>(*v);
  if (auto v = t.choice("behaviour", behaviours)) f.behaviour = *v;
  if (auto v = t.choice("channel-order", orders)) f.channel_order = *v;
  if (auto v = t.choice("backend", backends)) f.backend = *v;
  if (auto v = t.integer("device", -1, SessionLimits::max_device)) f.device = static_cast<int>(*v);
  if (auto v = t.choice("precision", precisions)) f.precision = *v;
  if (f.backend == "vulkan") {
    context.needs.gpus.push_back(
        {f.device, "stream '" + stream + "'", t.position(t.has("device") ? "device" : "backend")});
  }
  return f;
}

StreamConfig read_stream(const TableReader& t, std::size_t index, ReadContext& context) {
  static constexpr std::array<std::string_view, 4> keys = {"name", "source", "flow", "sink"};
  t.allow_only(keys);
  StreamConfig s;
  s.where = t.where();
  if (auto name = t.string("name", Need::required)) {
    if (const auto problem = check_name(*name); !problem.empty()) {
      t.report("name", "expected " + problem + ", got \"" + *name + "\"");
    } else {
      s.name = *name;
    }
  }
  // Messages about this stream's parts name it; without a usable name, by its place.
  const std::string label = s.name.empty() ? "#" + std::to_string(index + 1) : s.name;

  if (const auto* source = t.table("source", Need::required,
                                   "a [stream.source] table with the type of source: \"v4l2\", \"libcamera\", "
                                   "\"uri\" or \"test\"")) {
    s.source = read_source(TableReader(*source, "[stream.source]", context.issues), label, context);
  }
  if (const auto* flow = t.table("flow", Need::required, "a [stream.flow] table with at least the model")) {
    const TableReader reader(*flow, "[stream.flow]", context.issues);
    s.flow = read_flow(reader, label, context);
    context.need_elements(pipeline::required_elements(pipeline::FlowStage{}), "stream '" + label + "'", reader.where());
  }
  const auto* sinks = t.table_array("sink", Need::required,
                                    "at least one [[stream.sink]] table of type \"files\", \"shm\", \"video\" or "
                                    "\"display\"");
  if (sinks && sinks->empty()) {
    t.report("sink",
             "expected at least one [[stream.sink]] table of type \"files\", \"shm\", \"video\" or "
             "\"display\"");
  }
  std::map<std::string, SourcePosition> sink_names;
  if (sinks) {
    for (std::size_t i = 0; i < sinks->size(); ++i) {
      const TableReader reader(*sinks->get(i)->as_table(), "[[stream.sink]]", context.issues);
      SinkConfig sink;
      if (!read_sink(reader, i, label, context, sink)) continue;
      const auto [it, inserted] = sink_names.try_emplace(sink.name, sink.where);
      if (!inserted) {
        reader.report("name", "sink \"" + sink.name + "\" is already defined in this stream at line " +
                                  std::to_string(it->second.line) + "; sink names must be unique in a stream");
      }
      s.sinks.push_back(std::move(sink));
    }
  }
  return s;
}

}  // namespace neuflow::daemon
