// neuflow convert: optical flow for every consecutive pair of frames of image pairs, folders
// of frames and videos, written as flow files with an index, optionally rendered.
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "common/model_path.hpp"
#include "common/session_options.hpp"
#include "convert/inputs.hpp"
#include "convert/interruption.hpp"
#include "convert/job.hpp"
#include "convert/progress.hpp"
#include "fetch_model/hash.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace neuflow::cli {

namespace {

struct ConvertArgs {
  std::string model;
  std::vector<std::string> inputs;
  std::vector<std::pair<std::string, std::string>> pairs;
  std::string output;
  SessionArgs session;
  // Words, mapped after parsing (CLI11 2.1 cannot print FlowFormat's default).
  std::string format = "flo";
  std::string viz = "none";
  std::string viz_mode = "flow";
  double max_flow = 20;
  bool resume = false;
  bool overwrite = false;
  std::int64_t max_frames = 0;
  std::string fps;     // --fps N or N/D
  std::string shard;   // --shard K/N
  std::string frames;  // --frames A:B
  std::string padding = "centred";
};

// "A:B" with 0 <= A < B, or "A:" (to the end): the pairs whose first frame is A <= n < B.
FrameRange parse_frames(const std::string& text) {
  long long first = -1, end = -1;
  char rest = 0;
  int n = std::sscanf(text.c_str(), "%lld:%lld%c", &first, &end, &rest);
  if (n == 1 && text.size() > 1 && text.back() == ':' && text.find(':') == text.size() - 1 && first >= 0) {
    return {first, std::nullopt};
  }
  if (n == 2 && first >= 0 && end > first) return {first, end};
  throw CommandError(kExitUsage,
                     "--frames wants A:B with 0 <= A < B (the pairs whose first frame is A to B-1, frames "
                     "counted from 0) or A: (to the end), got '" +
                         text + "'");
}

// "N" or "N/D" frames per second, positive.
pipeline::FrameRate parse_rate(const std::string& text) {
  int numerator = 0, denominator = 1;
  char rest = 0;
  const int n = std::sscanf(text.c_str(), "%d/%d%c", &numerator, &denominator, &rest);
  if ((n == 1 || n == 2) && numerator > 0 && denominator > 0 && numerator <= 1000 * denominator) {
    return {numerator, denominator};
  }
  throw CommandError(kExitUsage,
                     "--fps wants frames per second as N or N/D (e.g. 15 or 30000/1001), got '" + text + "'");
}

struct Shard {
  std::size_t index = 0;  // K, from 0
  std::size_t count = 1;  // N
};

// "K/N" with 0 <= K < N: the K-th of N shards, counted from 0 (SLURM_ARRAY_TASK_ID,
// JOB_COMPLETION_INDEX).
Shard parse_shard(const std::string& text) {
  long k = -1, n = 0;
  char rest = 0;
  if (std::sscanf(text.c_str(), "%ld/%ld%c", &k, &n, &rest) == 2 && n > 0 && k >= 0 && k < n) {
    return {static_cast<std::size_t>(k), static_cast<std::size_t>(n)};
  }
  throw CommandError(kExitUsage,
                     "--shard wants K/N with 0 <= K < N (this job's index from 0, and the number of "
                     "jobs), got '" +
                         text + "'");
}

int terminal_width(int fd) {
  winsize size{};
  if (::ioctl(fd, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

std::string pairs_text(std::int64_t n) { return std::to_string(n) + (n == 1 ? " pair" : " pairs"); }

// "<input>: FAILED: <reason>", without naming the input twice when the reason starts with it.
std::string failure_text(const InputSpec& input, const InputError& error) {
  std::string reason = error.what();
  if (reason.rfind(input.label + ": ", 0) == 0) reason.erase(0, input.label.size() + 2);
  return input.label + ": FAILED: " + reason;
}

std::string summary_line(const InputSpec& input, const InputOutcome& outcome) {
  if (outcome.error) return "  " + failure_text(input, *outcome.error);
  const std::int64_t pairs = outcome.pairs_written + outcome.pairs_skipped;
  char timing[64];
  std::snprintf(timing, sizeof timing, " in %s", Progress::format_duration(outcome.seconds).c_str());
  std::string line = "  " + input.label + " -> " + outcome.output.string() + ": " + pairs_text(pairs) + " (" +
                     std::to_string(outcome.pairs_written) + " written, " + std::to_string(outcome.pairs_skipped) +
                     " skipped)" + timing;
  if (outcome.pairs_written > 0 && outcome.seconds > 0) {
    char rate[48];
    std::snprintf(rate, sizeof rate, ", %.2f pairs/s", static_cast<double>(outcome.pairs_written) / outcome.seconds);
    line += rate;
  }
  return line;
}

// "interrupted: 7 of 19 pairs of IN written (2 inputs not started); run again with --resume",
// with the shell's exit code for the signal (130 for Ctrl-C).
CommandError interrupted(const InputSpec& input, const InputOutcome& outcome, std::size_t not_started) {
  const std::int64_t done = outcome.pairs_written + outcome.pairs_skipped;
  std::string text = "interrupted: " + std::to_string(done) +
                     (outcome.total_pairs ? " of " + std::to_string(*outcome.total_pairs) : std::string()) +
                     " pairs of " + input.label + " written";
  if (not_started > 0) text += " (" + std::to_string(not_started) + " more inputs not started)";
  return CommandError(128 + interruption_signal(), text + "; run again with --resume");
}

// What this run makes its flows with. The backend is the one the session opened (auto names
// where it ran); the model, its content.
pipeline::OutputRecord record_of(const std::string& model_path, const std::string& format, const std::string& padding,
                                 const model::FlowSession& session) {
  const model::SessionOptions& o = session.options();
  const std::string& where = session.backend_description();
  std::string model_sha1;
  try {
    model_sha1 = git_blob_sha1_of_file(model_path);
  } catch (const std::exception& e) {
    throw CommandError(kExitNoInput, e.what());
  }
  return {model_sha1,
          o.iterations.s16,
          o.iterations.s8,
          o.model_width,
          o.model_height,
          std::string(model::channel_order_name(o.network_order)),
          where.substr(0, where.find(' ')),
          std::string(model::precision_name(o.precision)),
          format,
          padding};
}

void run_convert(const ConvertArgs& a) {
  const model::SessionOptions options = session_options(a.session);
  if (a.inputs.empty() && a.pairs.empty())
    throw CommandError(kExitUsage, "nothing to convert: give INPUT... or --pair A B");
  const std::optional<pipeline::FrameRate> image_rate =
      a.fps.empty() ? std::nullopt : std::optional<pipeline::FrameRate>(parse_rate(a.fps));
  const Shard shard = a.shard.empty() ? Shard{} : parse_shard(a.shard);
  const std::optional<FrameRange> frames = a.frames.empty() ? std::nullopt : std::optional(parse_frames(a.frames));
  if (frames && a.max_frames > 0)
    throw CommandError(kExitUsage, "--frames and --max-frames both limit the frames: give one");
  if (a.padding == "bottom" && (options.model_width > 0 || options.model_height > 0)) {
    throw CommandError(kExitUsage,
                       "--padding bottom pads frames that run at their own size: leave out --model-width and "
                       "--model-height (frames resized to a model size are not padded)");
  }

  const std::string model_path = resolve_model(a.model, "convert");
  std::shared_ptr<const model::FlowModel> model;
  try {
    model = model::FlowModel::load(model_path);
  } catch (const model::CheckpointError& e) {
    throw CommandError(exit_code_for(e), e.what());
  }
  model::FlowSession session(model, options);
  std::string announced = announce_backend(session, "convert");

  ConvertSettings settings;
  settings.output_dir = a.output;
  settings.format = a.format == "npy"   ? flow::FlowFormat::npy
                    : a.format == "png" ? flow::FlowFormat::kitti_png
                                        : flow::FlowFormat::flo;
  settings.viz = a.viz == "png" ? VizMode::png : a.viz == "video" ? VizMode::video : VizMode::none;
  settings.viz_look = a.viz_mode == "overlay" ? VizLook::overlay : VizLook::flow;
  settings.max_flow = a.max_flow;
  settings.resume = a.resume;
  settings.overwrite = a.overwrite;
  settings.record = record_of(model_path, a.format, a.padding, session);
  if (a.padding == "bottom") settings.padding = eval::PadMode::bottom;
  settings.max_frames = a.max_frames;
  settings.frames = frames;
  settings.image_rate = image_rate;

  const int fd = ::fileno(stderr);
  const bool terminal = ::isatty(fd) != 0;
  Progress progress(stderr, terminal, terminal ? terminal_width(fd) : 80);

  // Every input is named as in a whole run before a shard takes its share, so the shards of one
  // command line write exactly the folders the whole run would.
  std::vector<InputSpec> inputs;
  {
    auto all = plan_inputs(a.inputs, a.pairs);
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (i % shard.count == shard.index) inputs.push_back(std::move(all[i]));
    }
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "neuflow convert: shard %s has no inputs (fewer inputs than shards)\n", a.shard.c_str());
    return;
  }
  std::vector<InputOutcome> outcomes;
  const InterruptionHandler interruption;
  for (const auto& input : inputs) {
    outcomes.push_back(convert_input(input, session, settings, progress));
    report_late_fallback(session, "convert", announced);
    // Said at once, so a long batch does not hide an early failure until the end.
    if (outcomes.back().error) progress.print(failure_text(input, *outcomes.back().error));
    if (outcomes.back().interrupted) throw interrupted(input, outcomes.back(), inputs.size() - outcomes.size());
  }

  std::size_t failed = 0;
  int exit_code = kExitOk;
  for (const auto& outcome : outcomes) {
    if (!outcome.error) continue;
    if (failed++ == 0) exit_code = outcome.error->exit_code;
  }
  std::fprintf(stderr, "neuflow convert: %zu input%s, %zu converted, %zu failed\n", inputs.size(),
               inputs.size() == 1 ? "" : "s", inputs.size() - failed, failed);
  for (std::size_t i = 0; i < inputs.size(); ++i)
    std::fprintf(stderr, "%s\n", summary_line(inputs[i], outcomes[i]).c_str());
  if (failed > 0) {
    throw CommandError(exit_code, "convert: " + std::to_string(failed) + " of " + std::to_string(inputs.size()) +
                                      " inputs failed (exit code of the first failure)");
  }
}

}  // namespace

void register_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* sub = app.add_subcommand(
      "convert",
      "Compute the flow of every consecutive pair of frames of each INPUT (a folder of frames in natural order, a "
      "video file or URI, or two images) into OUTPUT/<input name>/: <frame>.flo|.npy|.png per pair, index.csv "
      "naming both frames of each flow, and optionally the colour rendering as viz/<frame>.png or viz.mp4. "
      "Video pairs are named frame_000123 (frame 123 -> 124), images by the first image's name");
  sub->add_option("--model,-m", args->model, kModelOptionHelp);
  sub->add_option("--output,-o", args->output, "Output folder; each input gets a sub-folder named after it")
      ->required();
  sub->add_option("--pair", args->pairs, "Two images to compute one flow between (repeatable)");
  sub->add_option("--format", args->format,
                  "Flow file format: flo (Middlebury), npy (H x W x 2 float32) or png (KITTI 16-bit)")
      ->check(CLI::IsMember({"flo", "npy", "png"}))
      ->capture_default_str();
  CLI::Option* viz =
      sub->add_option(
             "--viz", args->viz,
             "Colour rendering of each flow: png (viz/<frame>.png), video (viz.mp4, H.264, at the video's frame "
             "rate; for images --fps, else the rate their timestamp names give, else 10 fps) or none")
          ->check(CLI::IsMember({"none", "png", "video"}))
          ->capture_default_str();
  sub->add_option("--viz-mode", args->viz_mode,
                  "What --viz shows: flow (the colours alone) or overlay (blended over the pair's first frame at "
                  "60 %, as the neuflowviz element's default)")
      ->check(CLI::IsMember({"flow", "overlay"}))
      ->capture_default_str()
      ->needs(viz);
  sub->add_option("--max-flow", args->max_flow,
                  "Flow magnitude (px) drawn fully saturated in --viz; fixed so colours mean the same in every frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->add_option("--padding", args->padding,
                  "How frames that run at their own size are padded to multiples of 16: centred (edge pixels "
                  "repeated evenly on each side, as the reference evaluation pads Sintel) or bottom (left and right "
                  "evenly, every row at the bottom, as it pads KITTI). For flows `neuflow eval --predictions` scores, "
                  "take the benchmark's: bottom for KITTI, centred for the others")
      ->check(CLI::IsMember({"centred", "bottom"}))
      ->capture_default_str();
  sub->add_flag("--resume", args->resume,
                "Keep flow files that already exist and read back complete at the frames' size; compute the rest. "
                "A folder whose settings.toml records other settings (model, iterations, model size, channel order, "
                "backend, precision, format) is refused (exit 64)");
  sub->add_flag("--overwrite", args->overwrite,
                "With --resume: recompute a folder made with other settings instead of refusing it");
  sub->add_option("--max-frames", args->max_frames, "Only the first N frames of each input (N-1 pairs); 0: all")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& value) {
            return !value.empty() && value.find_first_not_of("0123456789") == std::string::npos
                       ? std::string()
                       : "wants 0 (all frames) or a number of frames, got '" + value + "'";  // after the name
          },
          "N"));
  sub->add_option("--fps", args->fps,
                  "Frame rate of images (N or N/D) for viz.mp4; default: from file names that are capture "
                  "timestamps (10, 13, 16 or 19 digits: s, ms, us, ns), else 10. Videos keep their own rate");
  sub->add_option("--shard", args->shard,
                  "Convert only the K-th of N shares of the inputs (K/N, K from 0: every N-th input starting at the "
                  "K-th), for job arrays; each input keeps the output folder name of a whole run");
  sub->add_option("--frames", args->frames,
                  "Convert only one range of each input (A:B, frames counted from 0: the pairs whose first frame "
                  "is A to B-1, i.e. frames A to B; A: to the end), for splitting a long video across jobs: ranges "
                  "that meet (0:1000, 1000:2000) share one frame and together hold every pair once. Writes "
                  "index.A-B.csv and viz.A-B.mp4")
      ->type_name("A:B");
  add_session_options(*sub, args->session);
  sub->add_option("INPUT", args->inputs,
                  "Folders of frames, video files or URIs, or two image files (a pair); several at once");
  sub->callback([args] { run_convert(*args); });
}

}  // namespace neuflow::cli
