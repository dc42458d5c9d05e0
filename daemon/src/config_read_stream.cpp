// One [[stream]]: its name, its [stream.flow] settings, and the source and sinks it holds.
#include <array>
#include <map>

#include "config_read.hpp"
#include "config_values.hpp"
#include "neuflow/model/session_option_docs.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {
namespace {

using Need = TableReader::Need;
using SessionLimits = model::SessionLimits;

}  // namespace

FlowConfig read_flow(const TableReader& t, const std::string& stream, ReadContext& context) {
  namespace docs = model::option_docs;
  // The element's property names (option_docs), which the command's options share.
  static constexpr std::array<std::string_view, 12> keys = {"model",
                                                            docs::iters_s16.name,
                                                            docs::iters_s8.name,
                                                            docs::model_width.name,
                                                            docs::model_height.name,
                                                            docs::threads.name,
                                                            docs::behaviour.name,
                                                            docs::channel_order.name,
                                                            docs::backend.name,
                                                            docs::device.name,
                                                            docs::precision.name,
                                                            docs::max_memory.name};
  using model::Backend, model::Behaviour, model::ChannelOrder, model::Precision;
  static constexpr std::array<std::string_view, 2> precisions = {model::precision_name(Precision::fp32),
                                                                 model::precision_name(Precision::fp16)};
  static constexpr std::array<std::string_view, 3> backends = {
      model::backend_name(Backend::automatic), model::backend_name(Backend::cpu), model::backend_name(Backend::vulkan)};
  static constexpr std::array<std::string_view, 3> behaviours = {model::behaviour_name(Behaviour::automatic),
                                                                 model::behaviour_name(Behaviour::live),
                                                                 model::behaviour_name(Behaviour::every_pair)};
  static constexpr std::array<std::string_view, 2> orders = {model::channel_order_name(ChannelOrder::rgb),
                                                             model::channel_order_name(ChannelOrder::bgr)};
  t.allow_only(keys);
  FlowConfig config;
  config.where = t.where();
  pipeline::FlowStage& f = config.stage;
  model::SessionOptions& session = f.session;
  if (auto model = t.string("model", Need::required)) {
    if (model->empty()) {
      t.report("model", "expected the path of a NeuFlow-V2 checkpoint (.pth), got an empty string");
    } else {
      f.model = context.need_path(PathNeed::Kind::checkpoint, *model, "model", t.position("model"));
    }
  }
  if (auto v = t.integer(docs::iters_s16.name, 0, SessionLimits::max_iterations_s16)) {
    session.iterations.s16 = static_cast<int>(*v);
  }
  if (auto v = t.integer(docs::iters_s8.name, 0, SessionLimits::max_iterations_s8))
    session.iterations.s8 = static_cast<int>(*v);
  const auto width = t.integer(docs::model_width.name, 0, SessionLimits::max_side);
  const auto height = t.integer(docs::model_height.name, 0, SessionLimits::max_side);
  const auto width_problem = width ? model::check_model_side(static_cast<int>(*width)) : std::nullopt;
  const auto height_problem = height ? model::check_model_side(static_cast<int>(*height)) : std::nullopt;
  if (width_problem) {
    t.report(docs::model_width.name, *width_problem);
  } else if (height_problem) {
    t.report(docs::model_height.name, *height_problem);
  } else if (width && height) {
    if ((*width == 0) != (*height == 0)) {
      t.report(*width == 0 ? docs::model_width.name : docs::model_height.name,
               "model-width and model-height go together: both 0 (the frames' own size) or both set");
    }
    session.model_width = static_cast<int>(*width);
    session.model_height = static_cast<int>(*height);
  } else if ((width && *width != 0) || (height && *height != 0)) {
    t.report(width ? docs::model_width.name : docs::model_height.name,
             "model-width and model-height go together: add " +
                 std::string(width ? docs::model_height.name : docs::model_width.name));
  }
  if (auto v = t.integer(docs::threads.name, 0, SessionLimits::max_threads)) session.threads = static_cast<int>(*v);
  // choice() accepts only the listed names, so each parse below succeeds.
  if (auto v = t.choice(docs::behaviour.name, behaviours))
    f.behaviour = model::parse_behaviour(*v).value_or(f.behaviour);
  if (auto v = t.choice(docs::channel_order.name, orders)) {
    session.network_order = model::parse_channel_order(*v).value_or(session.network_order);
  }
  if (auto v = t.choice(docs::backend.name, backends))
    session.backend = model::parse_backend(*v).value_or(session.backend);
  if (auto v = t.integer(docs::device.name, -1, SessionLimits::max_device)) session.device = static_cast<int>(*v);
  if (auto v = t.integer(docs::max_memory.name, 0, SessionLimits::max_memory_mb)) {
    session.max_memory_mb = static_cast<int>(*v);
  }
  if (auto v = t.choice(docs::precision.name, precisions)) {
    session.precision = model::parse_precision(*v).value_or(session.precision);
  }
  if (session.backend == Backend::vulkan) {
    context.needs.gpus.push_back({session.device, "stream '" + stream + "'",
                                  t.position(t.has(docs::device.name) ? docs::device.name : docs::backend.name)});
  }
  return config;
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
