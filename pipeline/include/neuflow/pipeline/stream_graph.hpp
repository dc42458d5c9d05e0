#pragma once
// A capture → flow → sink graph as a GStreamer pipeline, built from its description by way of
// its plan (graph_plan.hpp):
//
//   source → videoconvert → neuflow → tee ─┬→ queue → <sink branch 0>
//                                           └→ queue → <sink branch 1> …
//
// Each sink branch is a bin of its own so that an error inside it can be told apart from an
// error of the source or the flow element, and the branch cut off without stopping the rest:
// a probe on its tee pad drops everything once the branch is marked failed (the mark is set
// from the bus's sync handler, in the thread that posted the error, before the failing
// element returns its flow error upstream).
#include <gst/gst.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "neuflow/pipeline/graph_description.hpp"

namespace neuflow::pipeline {

struct SinkBranch {
  std::string name;              // NamedSink::name
  std::string kind;              // sink_kind(): "files", "shm", "video-file", "rtsp", "udp", "display"
  GstElement* bin = nullptr;     // our reference; in the pipeline until removed
  GstPad* tee_pad = nullptr;     // our reference to the tee's request pad
  GstElement* writer = nullptr;  // the element counting "flows-written" (files, shm), or null; in `bin`
  std::atomic<bool> failed{false};
  bool removed = false;  // taken out of the pipeline after failing (main thread only)
};

// A sink that could not be built when the pipeline was; the stream runs without it.
struct UnbuiltSink {
  std::string name;
  std::string reason;
};

// Owns the pipeline (one reference) and the tee pads.
class StreamGraph {
 public:
  StreamGraph() = default;
  ~StreamGraph();
  StreamGraph(const StreamGraph&) = delete;
  StreamGraph& operator=(const StreamGraph&) = delete;

  GstElement* pipeline() const { return pipeline_; }
  GstElement* flow_element() const { return flow_; }
  std::vector<std::unique_ptr<SinkBranch>>& sinks() { return sinks_; }
  const std::vector<UnbuiltSink>& unbuilt_sinks() const { return unbuilt_; }

  // The branch an element belongs to, or nullptr when it is outside every sink branch.
  SinkBranch* branch_of(GstObject* element);

  // Takes a failed branch out of the running pipeline (main thread).
  void remove_branch(SinkBranch& branch);

  size_t live_branches() const;

 private:
  friend std::unique_ptr<StreamGraph> build_stream_graph(const GraphDescription&, const std::string&);
  GstElement* pipeline_ = nullptr;
  GstElement* flow_ = nullptr;
  GstElement* tee_ = nullptr;
  std::vector<std::unique_ptr<SinkBranch>> sinks_;
  std::vector<UnbuiltSink> unbuilt_;
};

// Builds the pipeline in NULL state; the flow element gets description.flow.session.threads.
// `instance` names the pipeline ("front" or "front#3" after restarts) in GStreamer's logs. A
// sink that cannot be built (its folder cannot be created, an element is missing) is left out
// and listed in unbuilt_sinks(); throws std::runtime_error naming the element or sink when the
// source, the flow stage or every sink cannot be built.
std::unique_ptr<StreamGraph> build_stream_graph(const GraphDescription& description, const std::string& instance);

}  // namespace neuflow::pipeline
