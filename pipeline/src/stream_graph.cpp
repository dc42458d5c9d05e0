#include "neuflow/pipeline/stream_graph.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <variant>

#include "neuflow/pipeline/graph_plan.hpp"
#include "neuflow/pipeline/output_record.hpp"

namespace neuflow::pipeline {

namespace {

namespace fs = std::filesystem;

void link(GstElement* a, GstElement* b) {
  if (!gst_element_link(a, b)) {
    throw std::runtime_error(std::string("cannot link ") + GST_ELEMENT_NAME(a) + " to " + GST_ELEMENT_NAME(b));
  }
}

// The chain's elements, added to `bin` and linked in order; returns the first and the last.
std::pair<GstElement*, GstElement*> add_chain(GstBin* bin, const ElementChain& chain) {
  std::vector<GstElement*> made;
  try {
    for (const auto& spec : chain) made.push_back(make_element(spec));
  } catch (...) {
    for (GstElement* e : made) gst_object_unref(gst_object_ref_sink(e));
    throw;
  }
  GstElement* prev = nullptr;
  for (GstElement* e : made) {
    gst_bin_add(bin, e);
    if (prev) link(prev, e);
    prev = e;
  }
  return {made.front(), made.back()};
}

// uridecodebin's pads appear once the stream is typed; link the first video one.
void on_decoded_pad(GstElement*, GstPad* pad, gpointer user_data) {
  auto* convert = static_cast<GstElement*>(user_data);
  GstCaps* caps = gst_pad_get_current_caps(pad);
  if (!caps) caps = gst_pad_query_caps(pad, nullptr);
  const bool video = caps && gst_caps_get_size(caps) > 0 &&
                     g_str_has_prefix(gst_structure_get_name(gst_caps_get_structure(caps, 0)), "video/");
  if (caps) gst_caps_unref(caps);
  if (!video) return;  // audio and subtitles are left unlinked
  GstPad* sink = gst_element_get_static_pad(convert, "sink");
  if (!gst_pad_is_linked(sink)) gst_pad_link(pad, sink);
  gst_object_unref(sink);
}

void create_folders(const std::vector<fs::path>& folders) {
  for (const auto& folder : folders) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) throw std::runtime_error("cannot create " + folder.string() + ": " + ec.message());
  }
}

// What a files sink's flows are made with, as `neuflow convert` records its folders; the backend
// as configured (auto stays auto), the network's own padding (centred).
OutputRecord files_sink_record(const FlowStage& flow, const std::string& model_hash, const FilesSink& sink) {
  const model::SessionOptions& o = flow.session;
  OutputRecord record;
  record.model_sha1 = model_hash;
  record.iters_s16 = o.iterations.s16;
  record.iters_s8 = o.iterations.s8;
  record.model_width = o.model_width;
  record.model_height = o.model_height;
  record.channel_order = std::string(model::channel_order_name(o.network_order));
  record.backend = std::string(model::backend_name(o.backend));
  record.precision = std::string(model::precision_name(o.precision));
  record.format = sink.format;
  return record;
}

GstPadProbeReturn drop_when_failed(GstPad*, GstPadProbeInfo*, gpointer user_data) {
  const auto* branch = static_cast<const SinkBranch*>(user_data);
  return branch->failed.load(std::memory_order_acquire) ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
}

}  // namespace

StreamGraph::~StreamGraph() {
  if (pipeline_) gst_element_set_state(pipeline_, GST_STATE_NULL);
  for (auto& b : sinks_) {
    if (b->tee_pad) {
      if (!b->removed && tee_) gst_element_release_request_pad(tee_, b->tee_pad);
      gst_object_unref(b->tee_pad);
    }
    if (b->bin) {
      if (b->removed) gst_element_set_state(b->bin, GST_STATE_NULL);
      gst_object_unref(b->bin);
    }
  }
  if (pipeline_) gst_object_unref(pipeline_);
}

SinkBranch* StreamGraph::branch_of(GstObject* element) {
  for (GstObject* o = element ? GST_OBJECT(gst_object_ref(element)) : nullptr; o;) {
    for (auto& b : sinks_) {
      if (o == GST_OBJECT(b->bin)) {
        gst_object_unref(o);
        return b.get();
      }
    }
    GstObject* parent = gst_object_get_parent(o);
    gst_object_unref(o);
    o = parent;
  }
  return nullptr;
}

size_t StreamGraph::live_branches() const {
  return static_cast<size_t>(std::count_if(sinks_.begin(), sinks_.end(),
                                           [](const auto& b) { return !b->failed.load(std::memory_order_acquire); }));
}

void StreamGraph::remove_branch(SinkBranch& branch) {
  if (branch.removed) return;
  branch.failed.store(true, std::memory_order_release);
  GstPad* sink_pad = gst_element_get_static_pad(branch.bin, "sink");
  gst_pad_unlink(branch.tee_pad, sink_pad);
  gst_object_unref(sink_pad);
  gst_element_release_request_pad(tee_, branch.tee_pad);
  gst_element_set_state(branch.bin, GST_STATE_NULL);
  // Without the branch the pipeline's EOS no longer waits for the failed sink.
  gst_bin_remove(GST_BIN(pipeline_), branch.bin);
  branch.removed = true;
  // The branch's error, posted while the pipeline was still on its way to PLAYING (a video
  // sink prerolls only once its encoder has filled its look-ahead), marked that state change
  // failed: the pipeline would stay PAUSED, its prerolled sinks blocking every branch, and so
  // the stream. Asked again, the state change goes on without the branch.
  GST_OBJECT_LOCK(pipeline_);
  const GstState target = GST_STATE_TARGET(pipeline_);
  GST_OBJECT_UNLOCK(pipeline_);
  if (target == GST_STATE_PLAYING || target == GST_STATE_PAUSED) gst_element_set_state(pipeline_, target);
}

std::unique_ptr<StreamGraph> build_stream_graph(const GraphDescription& description, const std::string& instance) {
  auto graph = std::make_unique<StreamGraph>();
  graph->pipeline_ = GST_ELEMENT(gst_object_ref_sink(gst_pipeline_new(instance.c_str())));
  auto* bin = GST_BIN(graph->pipeline_);

  const auto [convert, flow] = add_chain(bin, plan_flow(description.flow));
  const SourcePlan source = plan_source(description.source);
  const auto [source_first, source_last] = add_chain(bin, source.chain);
  if (source.dynamic) {
    g_signal_connect(source_first, "pad-added", G_CALLBACK(on_decoded_pad), convert);
  } else {
    link(source_last, convert);
  }
  GstElement* tee = add_chain(bin, {element("tee", "tee").set("allow-not-linked", "true")}).first;
  link(flow, tee);
  graph->flow_ = flow;
  graph->tee_ = tee;

  PlanContext context;
  context.first_free_index = next_free_index;
  std::string model_hash;  // the flow stage's model's, once a files sink needs it
  for (const NamedSink& sink : description.sinks) {
    // A branch is built outside the pipeline, so one that cannot be built (its folder cannot
    // be created, an element is missing) leaves nothing behind and the other sinks still run.
    auto branch = std::make_unique<SinkBranch>();
    branch->name = sink.name;
    branch->kind = sink_kind(sink.settings);
    branch->bin = GST_ELEMENT(gst_object_ref_sink(gst_bin_new(("sink-" + sink.name).c_str())));
    try {
      const SinkPlan plan = plan_sink(description.name, sink, context);
      create_folders(plan.folders);
      // A folder of flows made otherwise is not added to: this sink is cut off, naming why.
      if (const auto* files = std::get_if<FilesSink>(&sink.settings)) {
        // The model is hashed once a graph, however many files sinks it has.
        if (model_hash.empty()) model_hash = model_sha1(description.flow.model);
        claim_folder(files->directory, files_sink_record(description.flow, model_hash, *files), "neuflowd");
      }
      const auto [first, last] = add_chain(GST_BIN(branch->bin), plan.chain);
      if (g_object_class_find_property(G_OBJECT_GET_CLASS(last), "flows-written")) branch->writer = last;
      GstPad* first_sink = gst_element_get_static_pad(first, "sink");
      GstPad* ghost = gst_ghost_pad_new("sink", first_sink);
      gst_object_unref(first_sink);
      gst_element_add_pad(branch->bin, ghost);
    } catch (const std::exception& e) {
      gst_object_unref(branch->bin);
      graph->unbuilt_.push_back({sink.name, e.what()});
      continue;
    }
    // The pipeline takes a reference of its own; ours is kept after a failed branch leaves
    // the pipeline, for branch_of().
    gst_bin_add(bin, branch->bin);
    GstPad* ghost = gst_element_get_static_pad(branch->bin, "sink");
    branch->tee_pad = gst_element_request_pad_simple(tee, "src_%u");
    const GstPadLinkReturn linked = gst_pad_link(branch->tee_pad, ghost);
    gst_object_unref(ghost);
    if (linked != GST_PAD_LINK_OK) throw std::runtime_error("cannot link the tee to sink " + sink.name);
    gst_pad_add_probe(branch->tee_pad,
                      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST),
                      drop_when_failed, branch.get(), nullptr);
    graph->sinks_.push_back(std::move(branch));
  }
  if (graph->sinks_.empty()) {
    std::string reasons;
    for (const auto& failed : graph->unbuilt_) {
      reasons += (reasons.empty() ? "" : "; ") + std::string("sink ") + failed.name + ": " + failed.reason;
    }
    throw std::runtime_error("no sink could be built (" + reasons + ")");
  }
  return graph;
}

}  // namespace neuflow::pipeline
