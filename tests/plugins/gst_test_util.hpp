#pragma once
// Helpers shared by the element tests: owning handles for GStreamer objects, frames with a
// synthetic NeuflowFlowMeta (no model involved), temporary directories.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gst/video/video.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "neuflow/gst/flow_meta.h"
#include "support/temp_dir.hpp"

namespace neuflow::gst_test {

struct HarnessDeleter {
  void operator()(GstHarness *h) const { gst_harness_teardown(h); }
};
struct BufferDeleter {
  void operator()(GstBuffer *b) const { gst_buffer_unref(b); }
};
struct ObjectDeleter {
  void operator()(gpointer o) const { gst_object_unref(o); }
};
struct MessageDeleter {
  void operator()(GstMessage *m) const { gst_message_unref(m); }
};
struct CapsDeleter {
  void operator()(GstCaps *c) const { gst_caps_unref(c); }
};
using HarnessPtr = std::unique_ptr<GstHarness, HarnessDeleter>;
using BufferPtr = std::unique_ptr<GstBuffer, BufferDeleter>;
using ElementPtr = std::unique_ptr<GstElement, ObjectDeleter>;
using BusPtr = std::unique_ptr<GstBus, ObjectDeleter>;
using MessagePtr = std::unique_ptr<GstMessage, MessageDeleter>;
using CapsPtr = std::unique_ptr<GstCaps, CapsDeleter>;

// Takes ownership of a new element (sinking its floating reference).
inline ElementPtr owned(GstElement *element) {
  return ElementPtr(element ? GST_ELEMENT(gst_object_ref_sink(element)) : nullptr);
}

// (u, v) of grid cell (x, y).
using FlowFunction = std::function<std::pair<float, float>(int x, int y)>;

inline std::vector<float> make_vectors(int width, int height, const FlowFunction &flow) {
  std::vector<float> uv(2 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto [u, v] = flow(x, y);
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      uv[2 * i] = u;
      uv[2 * i + 1] = v;
    }
  }
  return uv;
}

// Attaches a flow grid of width × height cells covering a frame_width × frame_height frame.
inline NeuflowFlowMeta *add_flow(GstBuffer *buffer, int width, int height, const std::vector<float> &uv,
                                 int frame_width, int frame_height) {
  GBytes *bytes = g_bytes_new(uv.data(), uv.size() * sizeof(float));
  NeuflowFlowMeta *meta =
      neuflow_buffer_add_flow_meta(buffer, static_cast<guint>(width), static_cast<guint>(height), bytes);
  g_bytes_unref(bytes);
  meta->frame_width = static_cast<guint>(frame_width);
  meta->frame_height = static_cast<guint>(frame_height);
  return meta;
}

// A frame of `format` filled with one byte value everywhere (alpha/padding included).
inline GstBuffer *make_frame(GstVideoFormat format, int width, int height, std::uint8_t fill) {
  GstVideoInfo info;
  gst_video_info_set_format(&info, format, static_cast<guint>(width), static_cast<guint>(height));
  GstBuffer *buffer = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&info), nullptr);
  gst_buffer_memset(buffer, 0, fill, GST_VIDEO_INFO_SIZE(&info));
  gst_buffer_add_video_meta(buffer, GST_VIDEO_FRAME_FLAG_NONE, format, static_cast<guint>(width),
                            static_cast<guint>(height));
  return buffer;
}

inline std::string caps_string(GstVideoFormat format, int width, int height) {
  return std::string("video/x-raw,format=") + gst_video_format_to_string(format) + ",width=" + std::to_string(width) +
         ",height=" + std::to_string(height) + ",framerate=30/1";
}

// The bytes of pixel (x, y) of a packed frame.
inline std::vector<std::uint8_t> pixel_bytes(GstBuffer *buffer, GstVideoFormat format, int width, int height, int x,
                                             int y) {
  GstVideoInfo info;
  gst_video_info_set_format(&info, format, static_cast<guint>(width), static_cast<guint>(height));
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return {};
  const int pstride = GST_VIDEO_INFO_COMP_PSTRIDE(&info, 0);
  const std::size_t offset =
      static_cast<std::size_t>(y) * static_cast<std::size_t>(GST_VIDEO_INFO_PLANE_STRIDE(&info, 0)) +
      static_cast<std::size_t>(x) * static_cast<std::size_t>(pstride);
  std::vector<std::uint8_t> out(map.data + offset, map.data + offset + pstride);
  gst_buffer_unmap(buffer, &map);
  return out;
}

// A fresh directory under the system's temporary directory, removed with its contents.
using neuflow::test::TempDir;

// The first error message on `bus`: its text for users and its debug details.
struct ErrorMessage {
  bool found = false;
  std::string message;
  std::string debug;
};

inline ErrorMessage pop_error(GstBus *bus) {
  ErrorMessage out;
  MessagePtr msg(gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR));
  if (!msg) return out;
  GError *error = nullptr;
  gchar *debug = nullptr;
  gst_message_parse_error(msg.get(), &error, &debug);
  out.found = true;
  if (error) out.message = error->message;
  if (debug) out.debug = debug;
  if (error) g_error_free(error);
  g_free(debug);
  return out;
}

}  // namespace neuflow::gst_test
