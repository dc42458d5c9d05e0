#pragma once
// GStreamer plumbing shared by the decoder and the encoder (internal to neuflow_pipeline).
#include <gst/gst.h>

#include <memory>
#include <optional>
#include <string>

#include "neuflow/pipeline/pipeline_error.hpp"

namespace neuflow::pipeline::detail {

// gst_init once per process, from whichever thread gets here first. Throws PipelineError
// (subject "GStreamer") when GStreamer cannot start.
void ensure_gstreamer();

struct ObjectUnref {
  void operator()(gpointer object) const { gst_object_unref(object); }
};
// Owns one reference to a GstObject (pipelines, elements, buses, pads).
template <typename T>
using GstPtr = std::unique_ptr<T, ObjectUnref>;

// gst_element_factory_make that names the missing element (and the Debian package that
// usually has it) instead of returning null. `subject` is the file the pipeline is for.
GstElement* make_element(const char* factory, const std::string& subject);

struct BusError {
  std::string text;       // GStreamer's message, with the reason for vague stream errors
  bool resource = false;  // a file or network resource could not be opened or read
};
// The first error waiting on the bus, without blocking.
std::optional<BusError> pop_bus_error(GstBus* bus);

}  // namespace neuflow::pipeline::detail
