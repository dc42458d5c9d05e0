#include "neuflow/pipeline/video_decoder.hpp"

#include <gst/app/gstappsink.h>
#include <gst/gst.h>
#include <gst/video/video.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "gst_support.hpp"
#include "network_host.hpp"
#include "neuflow/pipeline/pipeline_error.hpp"

namespace neuflow::pipeline {

using detail::GstPtr;
using Kind = PipelineError::Kind;

namespace {

// How long one wait for a frame lasts before the bus is checked for errors again.
constexpr GstClockTime kPollInterval = 100 * GST_MSECOND;
// Frames the decoder may hold ahead of the caller: enough to overlap decoding with the
// caller's work, few enough that a long video never piles up in memory.
constexpr guint kQueuedFrames = 2;

bool looks_like_uri(const std::string& source) {
  return source.find("://") != std::string::npos && gst_uri_is_valid(source.c_str());
}

std::string to_uri(const std::string& source) {
  if (looks_like_uri(source)) return source;
  std::error_code ec;
  const auto status = std::filesystem::status(source, ec);
  if (!std::filesystem::exists(status)) throw PipelineError(Kind::not_found, source, "no such file");
  if (std::filesystem::is_directory(status))
    throw PipelineError(Kind::not_found, source, "is a folder, not a video file");
  GError* error = nullptr;
  gchar* uri = gst_filename_to_uri(source.c_str(), &error);
  if (!uri) {
    const std::string problem = error ? error->message : "cannot be turned into a URI";
    g_clear_error(&error);
    throw PipelineError(Kind::not_found, source, problem);
  }
  std::string result(uri);
  g_free(uri);
  return result;
}

}  // namespace

struct VideoDecoder::Impl {
  std::string source;
  std::string uri;  // what uridecodebin opens
  GstPtr<GstElement> pipeline;
  GstElement* convert = nullptr;  // owned by the pipeline
  GstElement* sink = nullptr;     // owned by the pipeline
  GstPtr<GstBus> bus;

  // Written on GStreamer's streaming threads by the decodebin signals.
  std::mutex link_mutex;
  bool video_linked = false;
  std::atomic<bool> any_stream{false};  // decodebin has exposed a pad: it has finished plugging
  std::atomic<bool> no_video{false};

  std::chrono::steady_clock::time_point started;
  std::chrono::milliseconds start_timeout{0};

  std::int64_t next_number = 0;
  FrameRate rate;
  std::optional<std::int64_t> frame_count;
  bool ended = false;

  [[noreturn]] void fail(Kind kind, const std::string& problem) {
    ended = true;
    throw PipelineError(kind, source, problem);
  }

  RgbFrame to_frame(GstSample* sample);
  void learn_stream_properties(const GstVideoInfo& info);
  static void on_pad_added(GstElement*, GstPad* pad, gpointer user_data);
  static void on_no_more_pads(GstElement*, gpointer user_data);
};

// decodebin exposes one pad per stream once it knows what the stream is; the first raw
// video one goes to videoconvert, the rest (audio, subtitles, more video) stay unlinked.
void VideoDecoder::Impl::on_pad_added(GstElement*, GstPad* pad, gpointer user_data) {
  auto* impl = static_cast<Impl*>(user_data);
  impl->any_stream = true;
  std::lock_guard lock(impl->link_mutex);
  if (impl->video_linked) return;
  GstCaps* caps = gst_pad_get_current_caps(pad);
  if (!caps) caps = gst_pad_query_caps(pad, nullptr);
  const bool is_video =
      caps && gst_caps_get_size(caps) > 0 && gst_structure_has_name(gst_caps_get_structure(caps, 0), "video/x-raw");
  if (caps) gst_caps_unref(caps);
  if (!is_video) return;
  GstPad* sink_pad = gst_element_get_static_pad(impl->convert, "sink");
  impl->video_linked = gst_pad_link(pad, sink_pad) == GST_PAD_LINK_OK;
  gst_object_unref(sink_pad);
}

void VideoDecoder::Impl::on_no_more_pads(GstElement*, gpointer user_data) {
  auto* impl = static_cast<Impl*>(user_data);
  std::lock_guard lock(impl->link_mutex);
  if (!impl->video_linked) impl->no_video = true;
}

VideoDecoder::VideoDecoder(const std::string& source, std::chrono::milliseconds start_timeout)
    : impl_(std::make_unique<Impl>()) {
  detail::ensure_gstreamer();
  auto& s = *impl_;
  s.source = source;
  s.start_timeout = start_timeout;
  s.uri = to_uri(source);
  const std::string& uri = s.uri;

  s.pipeline.reset(GST_ELEMENT(gst_object_ref_sink(gst_pipeline_new("neuflow-decoder"))));
  GstElement* decode = detail::make_element("uridecodebin", source);
  gst_bin_add(GST_BIN(s.pipeline.get()), decode);  // the bin owns each element from here on
  s.convert = detail::make_element("videoconvert", source);
  gst_bin_add(GST_BIN(s.pipeline.get()), s.convert);
  s.sink = detail::make_element("appsink", source);
  gst_bin_add(GST_BIN(s.pipeline.get()), s.sink);

  g_object_set(decode, "uri", uri.c_str(), nullptr);
  GstCaps* rgb = gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "RGB", nullptr);
  gst_app_sink_set_caps(GST_APP_SINK(s.sink), rgb);
  gst_caps_unref(rgb);
  gst_app_sink_set_max_buffers(GST_APP_SINK(s.sink), kQueuedFrames);
  gst_app_sink_set_drop(GST_APP_SINK(s.sink), FALSE);
  // Decode as fast as possible, not at the video's playback speed.
  g_object_set(s.sink, "sync", FALSE, nullptr);
  if (!gst_element_link(s.convert, s.sink)) {
    throw PipelineError(Kind::failed, source, "cannot link videoconvert to appsink");
  }
  g_signal_connect(decode, "pad-added", G_CALLBACK(&Impl::on_pad_added), &s);
  g_signal_connect(decode, "no-more-pads", G_CALLBACK(&Impl::on_no_more_pads), &s);

  s.bus.reset(gst_element_get_bus(s.pipeline.get()));
  s.started = std::chrono::steady_clock::now();
  if (gst_element_set_state(s.pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    const auto error = detail::pop_bus_error(s.bus.get());
    gst_element_set_state(s.pipeline.get(), GST_STATE_NULL);
    if (!error) throw PipelineError(Kind::undecodable, source, "GStreamer cannot start decoding it");
    if (auto host = detail::unresolvable_host(s.uri)) throw PipelineError(Kind::not_found, source, *host);
    throw PipelineError(error->resource ? Kind::not_found : Kind::undecodable, source, error->text);
  }
}

VideoDecoder::~VideoDecoder() {
  // Stops and joins the streaming threads before the state their callbacks use goes away.
  if (impl_->pipeline) gst_element_set_state(impl_->pipeline.get(), GST_STATE_NULL);
}

const std::string& VideoDecoder::source() const { return impl_->source; }
FrameRate VideoDecoder::frame_rate() const { return impl_->rate; }
std::optional<std::int64_t> VideoDecoder::frame_count_estimate() const { return impl_->frame_count; }

std::optional<RgbFrame> VideoDecoder::next() {
  auto& s = *impl_;
  if (s.ended) return std::nullopt;
  for (;;) {
    if (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(s.sink), kPollInterval)) {
      try {
        RgbFrame frame = s.to_frame(sample);
        gst_sample_unref(sample);
        return frame;
      } catch (...) {
        gst_sample_unref(sample);
        throw;
      }
    }
    // Frames decoded before a failure have been handed out by now; the failure comes next.
    if (s.no_video) s.fail(Kind::undecodable, "has no video stream");
    if (const auto error = detail::pop_bus_error(s.bus.get())) {
      if (auto host = detail::unresolvable_host(s.uri)) s.fail(Kind::not_found, *host);
      s.fail(error->resource ? Kind::not_found : Kind::undecodable, error->text);
    }
    if (gst_app_sink_is_eos(GST_APP_SINK(s.sink))) {
      s.ended = true;
      if (s.next_number == 0) throw PipelineError(Kind::undecodable, s.source, "the video has no frames");
      return std::nullopt;
    }
    if (!s.any_stream && std::chrono::steady_clock::now() - s.started > s.start_timeout) {
      char seconds[32];
      std::snprintf(seconds, sizeof seconds, "%g", static_cast<double>(s.start_timeout.count()) / 1000.0);
      s.fail(Kind::undecodable, std::string("GStreamer found no stream to decode within ") + seconds +
                                    " s; the file is probably damaged or incomplete");
    }
  }
}

RgbFrame VideoDecoder::Impl::to_frame(GstSample* sample) {
  GstVideoInfo info;
  GstCaps* caps = gst_sample_get_caps(sample);
  if (!caps || !gst_video_info_from_caps(&info, caps)) fail(Kind::failed, "decoded frame without usable caps");
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  GstVideoFrame video_frame;
  if (!buffer || !gst_video_frame_map(&video_frame, &info, buffer, GST_MAP_READ)) {
    fail(Kind::failed, "cannot map a decoded frame");
  }
  RgbFrame frame;
  frame.width = GST_VIDEO_INFO_WIDTH(&info);
  frame.height = GST_VIDEO_INFO_HEIGHT(&info);
  const std::size_t row_bytes = 3 * static_cast<std::size_t>(frame.width);
  frame.rgb.resize(row_bytes * static_cast<std::size_t>(frame.height));
  const auto* data = static_cast<const std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&video_frame, 0));
  const std::size_t stride = static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&video_frame, 0));
  // GStreamer pads RGB rows to 4 bytes; the frame we hand out is packed.
  for (int y = 0; y < frame.height; ++y) {
    std::memcpy(frame.rgb.data() + y * row_bytes, data + y * stride, row_bytes);
  }
  gst_video_frame_unmap(&video_frame);
  frame.number = next_number++;
  if (GST_BUFFER_PTS_IS_VALID(buffer)) frame.pts_ns = static_cast<std::int64_t>(GST_BUFFER_PTS(buffer));
  if (frame.number == 0) learn_stream_properties(info);
  return frame;
}

void VideoDecoder::Impl::learn_stream_properties(const GstVideoInfo& info) {
  if (GST_VIDEO_INFO_FPS_N(&info) > 0 && GST_VIDEO_INFO_FPS_D(&info) > 0) {
    rate = FrameRate{GST_VIDEO_INFO_FPS_N(&info), GST_VIDEO_INFO_FPS_D(&info)};
  }
  gint64 duration = 0;
  if (rate.known() && gst_element_query_duration(pipeline.get(), GST_FORMAT_TIME, &duration) && duration > 0) {
    frame_count = static_cast<std::int64_t>(
        gst_util_uint64_scale_round(static_cast<guint64>(duration), static_cast<guint64>(rate.numerator),
                                    static_cast<guint64>(rate.denominator) * GST_SECOND));
  }
}

}  // namespace neuflow::pipeline
