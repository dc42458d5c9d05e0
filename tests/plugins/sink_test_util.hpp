#pragma once
// Helpers for the sink tests (neuflowshmsink, neuflowsink retention): sinks started under a
// GstHarness with an error bus, and buffers carrying a synthetic flow with full metadata.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "gst_test_util.hpp"

namespace neuflow::gst_test {

using Properties = std::vector<std::pair<const char *, std::string>>;

inline ElementPtr make_element(const char *factory, const Properties &properties) {
  ElementPtr element = owned(gst_element_factory_make(factory, nullptr));
  if (!element) return element;
  for (const auto &[name, value] : properties) gst_util_set_object_arg(G_OBJECT(element.get()), name, value.c_str());
  return element;
}

// A started sink (the harness sets it to PLAYING) whose messages go to `bus`.
struct RunningSink {
  ElementPtr element;
  BusPtr bus;
  HarnessPtr harness;

  GstFlowReturn push(GstBuffer *buffer) { return gst_harness_push(harness.get(), buffer); }
  // Stops the sink (PLAYING -> NULL), as the end of a pipeline does.
  void stop() { harness.reset(); }
};

inline RunningSink start_sink(const char *factory, const Properties &properties) {
  RunningSink s;
  s.element = make_element(factory, properties);
  if (!s.element) return s;
  s.bus.reset(gst_bus_new());
  gst_element_set_bus(s.element.get(), s.bus.get());
  s.harness.reset(gst_harness_new_with_element(s.element.get(), "sink", nullptr));
  gst_harness_set_src_caps_str(s.harness.get(), caps_string(GST_VIDEO_FORMAT_RGBA, 32, 24).c_str());
  return s;
}

// Starting `factory` (READY -> PAUSED) fails with one error, whose message is returned.
inline ErrorMessage start_error(const char *factory, const Properties &properties) {
  ElementPtr element = make_element(factory, properties);
  if (!element) return {};
  BusPtr bus(gst_bus_new());
  gst_element_set_bus(element.get(), bus.get());
  const GstStateChangeReturn ret = gst_element_set_state(element.get(), GST_STATE_PAUSED);
  ErrorMessage error = pop_error(bus.get());
  // Reported once: no generic "state change failed" error from GstBaseSink after ours.
  const ErrorMessage second = pop_error(bus.get());
  EXPECT_FALSE(second.found) << factory << " posted a second error: " << second.message;
  gst_element_set_state(element.get(), GST_STATE_NULL);
  if (ret != GST_STATE_CHANGE_FAILURE) error.found = false;
  return error;
}

struct FlowSpec {
  int width = 8, height = 6;
  guint64 from_frame = 0, to_frame = 1;
  GstClockTime from_pts = 0, to_pts = 33333333;
  float offset = 0.f;  // makes each flow's vectors distinct
  guint model_width = 64, model_height = 48;
  guint iters_s16 = 1, iters_s8 = 8;
  GstClockTime inference_time = 12345678;
  int frame_width = 32, frame_height = 24;
};

inline std::vector<float> vectors_of(const FlowSpec &f) {
  return make_vectors(f.width, f.height, [&](int x, int y) {
    // Multiples of 1/64, so that every format keeps them exact.
    return std::pair{f.offset + static_cast<float>(x) / 4.f, -static_cast<float>(y) / 8.f - f.offset};
  });
}

inline GstBuffer *buffer_with_flow(const FlowSpec &f) {
  GstBuffer *buffer = gst_buffer_new();
  GST_BUFFER_PTS(buffer) = f.to_pts;
  NeuflowFlowMeta *meta = add_flow(buffer, f.width, f.height, vectors_of(f), f.frame_width, f.frame_height);
  meta->from_frame = f.from_frame;
  meta->to_frame = f.to_frame;
  meta->from_pts = f.from_pts;
  meta->to_pts = f.to_pts;
  meta->model_width = f.model_width;
  meta->model_height = f.model_height;
  meta->iters_s16 = f.iters_s16;
  meta->iters_s8 = f.iters_s8;
  meta->inference_time = f.inference_time;
  return buffer;
}

// The n-th flow of a stream: distinct vectors and consecutive frames.
inline FlowSpec nth_flow(int n, int width = 8, int height = 6) {
  FlowSpec f;
  f.width = width;
  f.height = height;
  f.from_frame = static_cast<guint64>(n);
  f.to_frame = static_cast<guint64>(n) + 1;
  f.from_pts = static_cast<GstClockTime>(n) * 33333333u;
  f.to_pts = static_cast<GstClockTime>(n + 1) * 33333333u;
  f.offset = static_cast<float>(n) * 0.25f;
  f.inference_time = 1000000u + static_cast<GstClockTime>(n);
  return f;
}

inline guint64 uint64_property(GstElement *element, const char *name) {
  guint64 value = 0;
  g_object_get(element, name, &value, nullptr);
  return value;
}

}  // namespace neuflow::gst_test
