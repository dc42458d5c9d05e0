#pragma once
// Converting one input of `neuflow convert`: every consecutive pair of its frames through
// the streaming session, each flow written to its own file, optionally rendered, and the
// sidecar index.
//
// Output layout, in <output>/<input's output_name>/:
//   <stem>.flo|.npy|.png  the flow from the frame named <stem> to the next one: the image's
//                          stem for folders, frame_000123 (frame 123 → 124) for videos,
//                          flow for a pair (its folder names both images)
//   viz/<stem>.png         its colour rendering (--viz png), alone or over the frame (--viz-mode)
//   viz.mp4                all renderings as an H.264 video (--viz video)
//   index.csv              one row per pair (see convert/index.hpp)
//   settings.toml          what made the flows (neuflow/pipeline/output_record.hpp)
// With --frames A:B the index and the video are index.A-B.csv and viz.A-B.mp4, so jobs that
// take other ranges of the same input write beside each other.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "convert/input_error.hpp"
#include "convert/inputs.hpp"
#include "convert/progress.hpp"
#include "neuflow/eval/padding.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/pipeline/frame_rate.hpp"
#include "neuflow/pipeline/output_record.hpp"

namespace neuflow::cli {

enum class VizMode { none, png, video };
// What a rendering shows: the flow's colours alone, or blended over the pair's first frame.
enum class VizLook { flow, overlay };

// The pairs whose first frame is A <= n < B (frames A to B, counted from 0): ranges that meet
// (0:100, 100:200) share one frame and together hold every pair of the whole input once.
struct FrameRange {
  std::int64_t first = 0;
  std::optional<std::int64_t> end;  // B; unset: to the input's last frame
  // "A-B" (or "A-end"), for the names of the range's index and video.
  std::string suffix() const;
};

struct ConvertSettings {
  std::filesystem::path output_dir;
  flow::FlowFormat format = flow::FlowFormat::flo;
  VizMode viz = VizMode::none;
  VizLook viz_look = VizLook::flow;
  double max_flow = 20;  // px at full saturation, fixed so colours mean the same in every frame
  bool resume = false;   // keep flow files that exist and read back at the right size
  // With resume: recompute a folder made with other settings instead of refusing it.
  bool overwrite = false;
  pipeline::OutputRecord record;     // what this run makes its flows with, written into each folder
  std::int64_t max_frames = 0;       // 0: every frame; else only the first max_frames of each input
  std::optional<FrameRange> frames;  // --frames A:B: one range of each input's pairs
  // The rate of viz.mp4 for images (a video keeps its own): unset, the rate the file names'
  // timestamps give, else 10 frames per second.
  std::optional<pipeline::FrameRate> image_rate;
  // --padding bottom: the frames padded here as the reference evaluation pads KITTI (all rows at
  // the bottom) and the flow cropped back; unset, the session pads them centred itself.
  std::optional<eval::PadMode> padding;
};

struct InputOutcome {
  std::filesystem::path output;             // the input's output folder
  std::int64_t pairs_written = 0;           // flows computed and written
  std::int64_t pairs_skipped = 0;           // flows kept from an earlier run (--resume)
  std::optional<std::int64_t> total_pairs;  // the input's pairs (its range's), where known
  bool interrupted = false;                 // stopped by a signal after its last complete pair (interruption.hpp)
  double seconds = 0;
  std::optional<InputError> error;
};

// Never throws for a problem with the input or its outputs: that ends up in error, after
// whatever could be written (and the index of it) has been written. Interrupted, it writes the
// index of the complete pairs and drops the video.
InputOutcome convert_input(const InputSpec& input, model::FlowSession& session, const ConvertSettings& settings,
                           Progress& progress);

}  // namespace neuflow::cli
