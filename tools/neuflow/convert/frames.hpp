#pragma once
// The frames of one `neuflow convert` input, in order, whatever it is: the two images of a
// pair, the images of a folder in natural order, or the frames of a video.
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/image_header.hpp"
#include "convert/inputs.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/pipeline/frame_rate.hpp"

namespace neuflow::cli {

struct Frame {
  cv::Mat pixels;                  // 8-bit, 3 channels
  model::ChannelOrder data_order;  // how `pixels` holds them (OpenCV: BGR, GStreamer: RGB)
  std::int64_t number = 0;         // 0-based position in the input
  // A video frame's presentation time; an image's capture time when the sequence's names are
  // timestamps (capture_times_ns), in ns since the epoch.
  std::optional<std::int64_t> pts_ns;
  std::string source;  // the image's file name; empty for video frames
  // Base name of the outputs of the pair that starts at this frame: the image's stem (its
  // whole file name where two images of the folder share a stem), or frame_000123 for video.
  std::string output_stem;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame, or nullopt after the last. Throws InputError naming the file at fault.
  virtual std::optional<Frame> next() = 0;
  // How many frames the input has, when known (for a video: an estimate, after next()).
  virtual std::optional<std::int64_t> frame_count() const = 0;
  // The rate for an encoded visualization; unknown for images.
  virtual pipeline::FrameRate frame_rate() const = 0;
};

// The frame rate that images named by their capture time imply: every name all digits, of one
// length, 10 (seconds), 13 (ms), 16 (µs) or 19 (ns since the epoch) digits, strictly
// increasing; the mean rate over the sequence, in thousandths of a frame per second. Unknown
// for anything else and for fewer than two images.
pipeline::FrameRate rate_from_timestamps(const std::vector<std::string>& stems);

// Each name's time in ns, when the names are such timestamps (the rule above, a single one too);
// empty otherwise.
std::vector<std::int64_t> capture_times_ns(const std::vector<std::string>& stems);

// Throws InputError when the input cannot be opened (missing, an empty folder…). An image whose
// header states a size that `check` refuses is an InputError before it is decoded.
std::unique_ptr<FrameSource> open_frames(const InputSpec& input, FrameSizeCheck check = {});

}  // namespace neuflow::cli
