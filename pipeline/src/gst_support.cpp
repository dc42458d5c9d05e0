#include "gst_support.hpp"

#include <mutex>
#include <string_view>
#include <utility>

namespace neuflow::pipeline::detail {

void ensure_gstreamer() {
  static std::once_flag once;
  static std::string failure;
  std::call_once(once, [] {
    GError* error = nullptr;
    if (!gst_init_check(nullptr, nullptr, &error)) {
      failure = error ? error->message : "gst_init failed";
      g_clear_error(&error);
    }
  });
  if (!failure.empty()) throw PipelineError(PipelineError::Kind::failed, "GStreamer", "cannot initialize: " + failure);
}

namespace {

// Where Debian ships the elements we use, for the "not installed" message.
std::string_view package_of(std::string_view factory) {
  if (factory == "x264enc") return "gstreamer1.0-plugins-ugly";
  if (factory == "h264parse") return "gstreamer1.0-plugins-bad";
  if (factory == "mp4mux" || factory == "matroskamux") return "gstreamer1.0-plugins-good";
  return "gstreamer1.0-plugins-base";
}

}  // namespace

GstElement* make_element(const char* factory, const std::string& subject) {
  GstElement* element = gst_element_factory_make(factory, nullptr);
  if (!element) {
    throw PipelineError(PipelineError::Kind::missing_element, subject,
                        std::string("the GStreamer element '") + factory +
                            "' is not installed (Debian: " + std::string(package_of(factory)) + ")");
  }
  return element;
}

std::optional<BusError> pop_bus_error(GstBus* bus) {
  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
  if (!message) return std::nullopt;
  GError* error = nullptr;
  gchar* debug = nullptr;
  gst_message_parse_error(message, &error, &debug);
  std::string text = error ? error->message : "unknown GStreamer error";
  // "Internal data stream error." alone says nothing; the last line of the debug string
  // holds the reason (e.g. "streaming stopped, reason not-negotiated (-4)").
  if (error && g_error_matches(error, GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED) && debug && *debug) {
    std::string_view details(debug);
    if (const auto newline = details.find_last_of('\n'); newline != std::string_view::npos) {
      details.remove_prefix(newline + 1);
    }
    text += " (" + std::string(details) + ")";
  }
  const bool resource = error && error->domain == GST_RESOURCE_ERROR;
  g_clear_error(&error);
  g_free(debug);
  gst_message_unref(message);
  return BusError{std::move(text), resource};
}

}  // namespace neuflow::pipeline::detail
