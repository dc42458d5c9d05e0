#include "test_media.hpp"

#include <gst/gst.h>

#include <stdexcept>

namespace neuflow::test {

void run_gst_pipeline(const std::string& description) {
  gst_init(nullptr, nullptr);
  GError* error = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
  if (!pipeline || error) {
    const std::string message = error ? error->message : "gst_parse_launch failed";
    g_clear_error(&error);
    if (pipeline) gst_object_unref(pipeline);
    throw std::runtime_error("cannot build '" + description + "': " + message);
  }
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* message = gst_bus_timed_pop_filtered(bus, 60 * GST_SECOND,
                                                   static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  std::string failure;
  if (!message) {
    failure = "timed out";
  } else if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    GError* err = nullptr;
    gst_message_parse_error(message, &err, nullptr);
    failure = err ? err->message : "error";
    g_clear_error(&err);
  }
  if (message) gst_message_unref(message);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  if (!failure.empty()) throw std::runtime_error("'" + description + "' failed: " + failure);
}

std::filesystem::path make_test_video(const std::filesystem::path& path, int frames, int width, int height) {
  run_gst_pipeline("videotestsrc num-buffers=" + std::to_string(frames) +
                   " pattern=ball ! video/x-raw,width=" + std::to_string(width) + ",height=" + std::to_string(height) +
                   ",framerate=10/1 ! videoconvert ! x264enc ! h264parse ! mp4mux ! filesink location=\"" +
                   path.string() + "\"");
  return path;
}

std::filesystem::path make_audio_only(const std::filesystem::path& path) {
  run_gst_pipeline("audiotestsrc num-buffers=10 ! wavenc ! filesink location=\"" + path.string() + "\"");
  return path;
}

std::string hidden_files(const std::filesystem::path& dir) {
  std::string names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (!name.empty() && name[0] == '.') names += name + " ";
  }
  return names;
}

}  // namespace neuflow::test
