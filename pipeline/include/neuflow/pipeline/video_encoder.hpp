#pragma once
// Encoding RGB frames into an H.264 video file: appsrc → videoconvert (to I420, which every
// player decodes) → x264enc → h264parse → mp4mux or matroskamux (by the extension: .mp4 or
// .mkv) → filesink.
//
// The file is written under a temporary name beside the target and renamed by finish(),
// after the muxer has written its index at end of stream, so the target path only ever
// holds a complete, playable file. An encoder destroyed without finish() (an error, an
// exception elsewhere) removes its temporary file and leaves the target untouched.
#include <filesystem>
#include <memory>

#include "neuflow/flow/visualize.hpp"
#include "neuflow/pipeline/frame_rate.hpp"

namespace neuflow::pipeline {

class VideoEncoder {
 public:
  // Frames must all be width × height. H.264 in 4:2:0 needs even sizes: an odd width or
  // height is encoded one pixel larger with the last column or row repeated. A rate that is
  // not known() is taken as 25 fps. Throws PipelineError: invalid_argument for an
  // extension other than .mp4/.mkv or an unusable size, missing_element when the encoder or
  // muxer is not installed, write_failed when the temporary file cannot be created.
  VideoEncoder(std::filesystem::path path, int width, int height, FrameRate rate);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // Queues one frame; waits while the encoder is more than a few frames behind. Throws
  // PipelineError when the size differs or the pipeline has failed (disk full…).
  void write(const flow::RgbImage& frame);

  // Ends the stream, waits until the file is complete and renames it to the target path.
  // Throws PipelineError (write_failed) if any of that fails; the target is then untouched.
  void finish();

  std::int64_t frames_written() const;
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace neuflow::pipeline
