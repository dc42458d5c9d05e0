#pragma once
// Decoding any video GStreamer can open (a file or a URI) into 8-bit RGB frames, in order:
// uridecodebin → videoconvert → appsink. Only the first video stream is used; audio and
// other streams are ignored. Decoding runs ahead of the caller by at most a couple of
// frames, so memory stays bounded however long the video is.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "neuflow/flow/visualize.hpp"
#include "neuflow/pipeline/frame_rate.hpp"

namespace neuflow::pipeline {

// One decoded frame: its pixels (rows top to bottom without padding, R, G, B) and where it is
// in the stream.
struct RgbFrame : flow::RgbImage {
  std::int64_t number = 0;             // 0-based position in the decoded stream
  std::optional<std::int64_t> pts_ns;  // presentation timestamp, when the stream has one
};

class VideoDecoder {
 public:
  // GStreamer's decodebin drops an error that a demuxer raises while it is still being
  // plugged in (a damaged or truncated file), after which nothing happens at all. No
  // stream found within this time counts as undecodable.
  static constexpr std::chrono::milliseconds kDefaultStartTimeout{20000};

  // `source` is a local path (checked to exist) or a URI (file://, http://, rtsp://…).
  // Starts decoding at once. Throws PipelineError: not_found for a missing file,
  // missing_element when GStreamer lacks a basic element.
  explicit VideoDecoder(const std::string& source, std::chrono::milliseconds start_timeout = kDefaultStartTimeout);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  // The next frame, or nullopt at the end of the stream. Throws PipelineError (undecodable)
  // when the source is not a video GStreamer can decode, has no video stream, or decoding
  // fails midway; frames decoded before the failure are returned first.
  std::optional<RgbFrame> next();

  // Known once the first frame has been returned (unknown for variable-rate streams).
  FrameRate frame_rate() const;
  // The number of frames from the stream's duration and frame rate, when both are known
  // (after the first frame); an estimate, as containers round durations.
  std::optional<std::int64_t> frame_count_estimate() const;

  const std::string& source() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace neuflow::pipeline
