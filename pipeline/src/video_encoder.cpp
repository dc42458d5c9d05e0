#include "neuflow/pipeline/video_encoder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <gst/app/gstappsrc.h>
#include <gst/gst.h>
#include <gst/video/video.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "gst_support.hpp"
#include "neuflow/pipeline/pipeline_error.hpp"

namespace neuflow::pipeline {

using detail::GstPtr;
using Kind = PipelineError::Kind;

namespace {

constexpr int kMaxSide = 16384;
// Frames that may wait in appsrc before write() waits for the encoder: a little slack for
// the encoder's threads, without holding a long video in memory.
constexpr guint64 kQueuedFrames = 4;
constexpr GstClockTime kQueuePoll = 5 * GST_MSECOND;
// Draining at end of stream only has the queued frames and x264's lookahead left to encode.
constexpr GstClockTime kFinishTimeout = 120 * GST_SECOND;
constexpr FrameRate kDefaultRate{25, 1};

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

const char* muxer_for(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".mp4") return "mp4mux";
  if (ext == ".mkv") return "matroskamux";
  throw PipelineError(Kind::invalid_argument, path.string(),
                      "the video's extension must be .mp4 or .mkv, not '" + path.extension().string() + "'");
}

std::string errno_text(int err) { return std::generic_category().message(err); }

// Creates the temporary file beside `path` (so the final rename stays on one file system),
// which also proves early, with a clear message, that the folder is writable.
std::filesystem::path create_temporary_sibling(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  const auto dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  for (int attempt = 0; attempt < 16; ++attempt) {
    const std::string name = "." + path.filename().string() + ".partial-" + std::to_string(::getpid()) + "-" +
                             std::to_string(counter.fetch_add(1));
    auto temp = dir / name;
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return temp;
    }
    if (errno != EEXIST) {
      throw PipelineError(Kind::write_failed, path.string(),
                          "cannot create a file in " + dir.string() + ": " + errno_text(errno));
    }
  }
  throw PipelineError(Kind::write_failed, path.string(), "cannot create a temporary file in " + dir.string());
}

}  // namespace

struct VideoEncoder::Impl {
  std::filesystem::path path;
  std::filesystem::path temp;
  int width = 0, height = 0;
  FrameRate rate;
  GstVideoInfo coded;  // the size and layout appsrc announces (even width and height)
  GstPtr<GstElement> pipeline;
  GstElement* src = nullptr;  // owned by the pipeline
  GstPtr<GstBus> bus;
  std::int64_t frames = 0;
  bool done = false;  // finished or failed: no more frames accepted

  [[noreturn]] void fail(Kind kind, const std::string& problem) {
    abandon();
    throw PipelineError(kind, path.string(), problem);
  }

  void fail_on_bus_error() {
    if (const auto error = detail::pop_bus_error(bus.get())) {
      fail(error->resource ? Kind::write_failed : Kind::failed, "encoding failed: " + error->text);
    }
  }

  // Stops the pipeline and removes the partial file; the target keeps whatever it had.
  void abandon() {
    done = true;
    if (pipeline) gst_element_set_state(pipeline.get(), GST_STATE_NULL);
    if (!temp.empty()) {
      std::error_code ec;
      std::filesystem::remove(temp, ec);
      temp.clear();
    }
  }

  GstBuffer* to_buffer(const flow::RgbImage& frame) const;
};

VideoEncoder::VideoEncoder(std::filesystem::path path, int width, int height, FrameRate rate)
    : impl_(std::make_unique<Impl>()) {
  auto& s = *impl_;
  s.path = std::move(path);
  s.width = width;
  s.height = height;
  s.rate = rate.known() ? rate : kDefaultRate;
  const char* muxer = muxer_for(s.path);
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide) {
    throw PipelineError(Kind::invalid_argument, s.path.string(),
                        "cannot encode frames of " + std::to_string(width) + "x" + std::to_string(height));
  }
  detail::ensure_gstreamer();
  const std::string subject = s.path.string();

  s.pipeline.reset(GST_ELEMENT(gst_object_ref_sink(gst_pipeline_new("neuflow-encoder"))));
  GstBin* bin = GST_BIN(s.pipeline.get());
  // Each element belongs to the bin as soon as it is made, so a later throw leaks nothing.
  const auto add = [&](const char* factory) {
    GstElement* element = detail::make_element(factory, subject);
    gst_bin_add(bin, element);
    return element;
  };
  s.src = add("appsrc");
  GstElement* convert = add("videoconvert");
  GstElement* filter = add("capsfilter");
  GstElement* encoder = add("x264enc");
  GstElement* parser = add("h264parse");
  GstElement* mux = add(muxer);
  GstElement* sink = add("filesink");

  const int coded_width = width + (width % 2), coded_height = height + (height % 2);
  gst_video_info_set_format(&s.coded, GST_VIDEO_FORMAT_RGB, static_cast<guint>(coded_width),
                            static_cast<guint>(coded_height));
  GST_VIDEO_INFO_FPS_N(&s.coded) = s.rate.numerator;
  GST_VIDEO_INFO_FPS_D(&s.coded) = s.rate.denominator;
  GstCaps* src_caps = gst_video_info_to_caps(&s.coded);
  gst_app_src_set_caps(GST_APP_SRC(s.src), src_caps);
  gst_caps_unref(src_caps);
  g_object_set(s.src, "format", GST_FORMAT_TIME, nullptr);
  // 4:2:0 is what browsers and hardware decoders play; x264 would otherwise pick 4:4:4.
  GstCaps* i420 = gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "I420", nullptr);
  g_object_set(filter, "caps", i420, nullptr);
  gst_caps_unref(i420);
  // Encoding is a small cost next to computing the flow; veryfast keeps it that way.
  gst_util_set_object_arg(G_OBJECT(encoder), "speed-preset", "veryfast");

  if (!gst_element_link_many(s.src, convert, filter, encoder, parser, mux, sink, nullptr)) {
    throw PipelineError(Kind::failed, subject,
                        std::string("cannot link the encoding pipeline (x264enc ! h264parse ! ") + muxer + ")");
  }
  s.temp = create_temporary_sibling(s.path);
  g_object_set(sink, "location", s.temp.c_str(), nullptr);

  s.bus.reset(gst_element_get_bus(s.pipeline.get()));
  if (gst_element_set_state(s.pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    s.fail_on_bus_error();
    s.fail(Kind::failed, "GStreamer cannot start the encoder");
  }
}

VideoEncoder::~VideoEncoder() {
  if (!impl_->done) impl_->abandon();
}

std::int64_t VideoEncoder::frames_written() const { return impl_->frames; }
const std::filesystem::path& VideoEncoder::path() const { return impl_->path; }

GstBuffer* VideoEncoder::Impl::to_buffer(const flow::RgbImage& frame) const {
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&coded), nullptr);
  GstVideoFrame mapped;
  if (!buffer || !gst_video_frame_map(&mapped, &coded, buffer, GST_MAP_WRITE)) {
    if (buffer) gst_buffer_unref(buffer);
    throw PipelineError(Kind::failed, path.string(), "cannot allocate a video frame");
  }
  auto* out = static_cast<std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&mapped, 0));
  const std::size_t stride = static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&mapped, 0));
  const std::size_t row_bytes = 3 * static_cast<std::size_t>(width);
  const int coded_height = GST_VIDEO_INFO_HEIGHT(&coded);
  const bool pad_column = GST_VIDEO_INFO_WIDTH(&coded) > width;
  for (int y = 0; y < coded_height; ++y) {
    // The padding row and column repeat the last real ones (see the constructor's contract).
    const int source_y = std::min(y, height - 1);
    std::uint8_t* row = out + y * stride;
    std::memcpy(row, frame.rgb.data() + source_y * row_bytes, row_bytes);
    if (pad_column) std::memcpy(row + row_bytes, row + row_bytes - 3, 3);
  }
  gst_video_frame_unmap(&mapped);

  const auto timestamp = [&](std::int64_t n) {
    return gst_util_uint64_scale(static_cast<guint64>(n), GST_SECOND * static_cast<guint64>(rate.denominator),
                                 static_cast<guint64>(rate.numerator));
  };
  GST_BUFFER_PTS(buffer) = timestamp(frames);
  GST_BUFFER_DURATION(buffer) = timestamp(frames + 1) - timestamp(frames);
  return buffer;
}

void VideoEncoder::write(const flow::RgbImage& frame) {
  auto& s = *impl_;
  if (s.done)
    throw PipelineError(Kind::invalid_argument, s.path.string(), "the encoder has already finished or failed");
  if (frame.width != s.width || frame.height != s.height ||
      frame.rgb.size() != 3 * static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height)) {
    throw PipelineError(Kind::invalid_argument, s.path.string(),
                        "frame of " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                            " given to an encoder of " + std::to_string(s.width) + "x" + std::to_string(s.height));
  }
  s.fail_on_bus_error();
  // Waits for the encoder instead of queueing without bound, watching for errors, which
  // would otherwise leave the queue full for ever.
  const guint64 limit = kQueuedFrames * GST_VIDEO_INFO_SIZE(&s.coded);
  while (gst_app_src_get_current_level_bytes(GST_APP_SRC(s.src)) > limit) {
    if (GstMessage* message = gst_bus_timed_pop_filtered(s.bus.get(), kQueuePoll, GST_MESSAGE_ERROR)) {
      // Put back (the bus takes it) for fail_on_bus_error to parse.
      gst_bus_post(s.bus.get(), message);
      s.fail_on_bus_error();
      s.fail(Kind::failed, "encoding failed");
    }
  }
  const GstFlowReturn result = gst_app_src_push_buffer(GST_APP_SRC(s.src), s.to_buffer(frame));
  if (result != GST_FLOW_OK) {
    s.fail_on_bus_error();
    s.fail(Kind::failed, std::string("the encoder refused a frame: ") + gst_flow_get_name(result));
  }
  ++s.frames;
}

void VideoEncoder::finish() {
  auto& s = *impl_;
  if (s.done)
    throw PipelineError(Kind::invalid_argument, s.path.string(), "the encoder has already finished or failed");
  if (s.frames == 0) s.fail(Kind::invalid_argument, "no frames to encode");
  gst_app_src_end_of_stream(GST_APP_SRC(s.src));
  // The muxer writes its index (the MP4 moov) when end of stream reaches it.
  GstMessage* message = gst_bus_timed_pop_filtered(s.bus.get(), kFinishTimeout,
                                                   static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  if (!message)
    s.fail(Kind::failed, "the encoder did not finish within " + std::to_string(kFinishTimeout / GST_SECOND) + " s");
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    gst_bus_post(s.bus.get(), message);  // the bus takes it; fail_on_bus_error parses it
    s.fail_on_bus_error();
    s.fail(Kind::failed, "encoding failed");
  }
  gst_message_unref(message);
  gst_element_set_state(s.pipeline.get(), GST_STATE_NULL);

  // Durable before it becomes visible, like the flow files.
  const int fd = ::open(s.temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    s.fail(Kind::write_failed, "cannot flush the encoded file to disk: " + errno_text(err));
  }
  ::close(fd);
  if (::rename(s.temp.c_str(), s.path.c_str()) != 0) {
    s.fail(Kind::write_failed, "cannot rename the finished file into place: " + errno_text(errno));
  }
  s.temp.clear();
  s.done = true;
}

}  // namespace neuflow::pipeline
