#include "convert/job.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include "common/exit_codes.hpp"
#include "convert/frames.hpp"
#include "convert/index.hpp"
#include "convert/interruption.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/figures.hpp"
#include "neuflow/flow/visualize.hpp"
#include "neuflow/pipeline/pipeline_error.hpp"
#include "neuflow/pipeline/video_encoder.hpp"

namespace neuflow::cli {

namespace fs = std::filesystem;

namespace {

// Images without timestamps in their names have no frame rate; this one plays a
// visualization at a watchable pace.
constexpr pipeline::FrameRate kImageSequenceRate{10, 1};

const char* extension_of(flow::FlowFormat format) {
  switch (format) {
    case flow::FlowFormat::flo: return ".flo";
    case flow::FlowFormat::kitti_png: return ".png";
    case flow::FlowFormat::npy: return ".npy";
  }
  return ".flo";
}

model::ImageView view_of(const Frame& frame) {
  return {frame.pixels.data, frame.pixels.cols, frame.pixels.rows, static_cast<std::ptrdiff_t>(frame.pixels.step[0]),
          frame.data_order};
}

std::string describe(const Frame& frame) {
  return frame.source.empty() ? "frame " + std::to_string(frame.number) : frame.source;
}

std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

// The flow in `path` when it reads back whole and at the frames' size: an interrupted or
// older run's file of another size does not count.
std::optional<flow::FlowField> read_complete_flow(const fs::path& path, int width, int height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  try {
    auto field = flow::read_flow(path);
    if (field.width == width && field.height == height) return field;
  } catch (const flow::FlowFileError&) {
  }
  return std::nullopt;
}

bool complete_png(const fs::path& path, int width, int height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    return image.cols == width && image.rows == height;
  } catch (const cv::Exception&) {
    return false;
  }
}

void create_folder(const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError(kExitCantCreate, folder.string() + ": cannot create the output folder: " + ec.message());
}

// index.csv, or index.A-B.csv for a range of the input's frames; the same for viz.mp4.
fs::path range_name(const char* stem, const char* extension, const std::optional<FrameRange>& frames) {
  return std::string(stem) + (frames ? "." + frames->suffix() : std::string()) + extension;
}

class Conversion {
 public:
  Conversion(const InputSpec& input, model::FlowSession& session, const ConvertSettings& settings, Progress& progress)
      : input_(input),
        session_(session),
        settings_(settings),
        progress_(progress),
        dir_(settings.output_dir / input.output_name),
        index_(dir_ / range_name("index", ".csv", settings.frames)) {}

  void run(InputOutcome& outcome);
  void finish_outputs();
  bool has_rows() const { return rows_ > 0; }
  void write_index() const { index_.write(); }

 private:
  void convert_pair(const Frame& from, const Frame& to, InputOutcome& outcome);
  flow::FlowField compute(const Frame& from, const Frame& to);
  void render(const flow::FlowField& field, const Frame& from, bool write_png);

  const InputSpec& input_;
  model::FlowSession& session_;
  const ConvertSettings& settings_;
  Progress& progress_;
  fs::path dir_;
  FlowIndex index_;
  std::int64_t rows_ = 0;
  std::unique_ptr<FrameSource> frames_;
  std::unique_ptr<pipeline::VideoEncoder> video_;
  bool session_holds_from_ = false;  // the session's last frame is the pair's first one
  bool resume_ = false;              // keep the folder's complete flows
};

// --resume keeps a folder's flows only when its record says they were made as this run makes
// them; otherwise it refuses the folder, or with --overwrite recomputes it.
bool may_resume(const fs::path& dir, const ConvertSettings& settings) {
  if (!settings.resume) return false;
  std::optional<pipeline::OutputRecord> was;
  try {
    was = pipeline::read_record(dir);
  } catch (const pipeline::OutputRecordError& e) {
    if (settings.overwrite) return false;
    throw InputError(kExitDataError, std::string(e.what()) + " (delete it, or give --overwrite)");
  }
  if (!was) return true;  // written before folders had records
  const std::vector<std::string> differences = pipeline::record_differences(*was, settings.record, "--");
  if (differences.empty()) return true;
  if (settings.overwrite) return false;
  std::string list;
  for (const auto& d : differences) list += (list.empty() ? "" : ", ") + d;
  throw InputError(kExitUsage, dir.string() + ": its flows were made with other settings: " + list +
                                   "; resume with those, or add --overwrite to recompute them");
}

void Conversion::run(InputOutcome& outcome) {
  frames_ = open_frames(input_, [this](int w, int h) { return session_.frame_problem(w, h); });
  create_folder(dir_);
  if (settings_.resume) remove_stale_partials(dir_);
  resume_ = may_resume(dir_, settings_);
  try {
    pipeline::write_record(dir_, settings_.record, "neuflow convert");
  } catch (const pipeline::OutputRecordError& e) {
    throw InputError(kExitCantCreate, e.what());
  }
  if (settings_.viz == VizMode::png) create_folder(dir_ / "viz");
  session_.reset();

  const FrameRange range = settings_.frames.value_or(FrameRange{});
  const std::int64_t first = range.first;
  const std::optional<std::int64_t>& end = range.end;
  const auto total_pairs = [&]() -> std::optional<std::int64_t> {
    auto count = frames_->frame_count();
    if (settings_.max_frames > 0) count = count ? std::min(*count, settings_.max_frames) : settings_.max_frames;
    if (!count) return std::nullopt;
    std::int64_t pairs = std::max<std::int64_t>(*count - 1, 0);
    if (end) pairs = std::min(pairs, *end);
    return std::max<std::int64_t>(pairs - first, 0);
  };
  // The output name is short and unique among the inputs; a full path would crowd the bar out.
  progress_.begin(input_.output_name, total_pairs());

  // A range starts at its first frame: the ones before it are decoded and dropped (the
  // stream starts afresh there, which gives the same flows as a whole run).
  std::optional<Frame> from = frames_->next();
  if (!from) throw InputError(kExitDataError, input_.label + ": has no frames");
  std::int64_t frames_read = 1;
  while (from && frames_read <= first) {
    from = frames_->next();
    ++frames_read;
  }
  if (!from) {
    throw InputError(kExitDataError, input_.label + ": has " + std::to_string(frames_read - 1) + " frames; --frames " +
                                         settings_.frames->suffix() + " starts after its last");
  }
  progress_.set_total(total_pairs());  // a video's length is known once it plays
  outcome.total_pairs = total_pairs();
  while ((settings_.max_frames == 0 || frames_read < settings_.max_frames) && (!end || frames_read <= *end)) {
    if (interruption_signal() != 0) {
      outcome.interrupted = true;
      return;
    }
    std::optional<Frame> to = frames_->next();
    if (!to) break;
    ++frames_read;
    if (to->pixels.size() != from->pixels.size()) {
      throw InputError(kExitDataError, describe(*to) + " is " + size_text(to->pixels) + " but " + describe(*from) +
                                           " is " + size_text(from->pixels) +
                                           ": all frames of an input need one size (a flow pairs two frames pixel "
                                           "by pixel): resize them to one, or convert each size as its own input");
    }
    convert_pair(*from, *to, outcome);
    from = std::move(to);
  }
  if (rows_ == 0 && settings_.frames) {
    throw InputError(kExitDataError, input_.label + ": --frames " + settings_.frames->suffix() +
                                         " holds a single frame of it; a flow needs at least two");
  }
  if (rows_ == 0) {
    throw InputError(kExitDataError, input_.label + ": has a single frame; a flow needs at least two");
  }
}

void Conversion::convert_pair(const Frame& from, const Frame& to, InputOutcome& outcome) {
  const int width = from.pixels.cols, height = from.pixels.rows;
  const std::string file = from.output_stem + extension_of(settings_.format);
  const fs::path flow_path = dir_ / file;
  const fs::path png_path = dir_ / "viz" / (from.output_stem + ".png");

  std::optional<flow::FlowField> field;
  if (resume_) field = read_complete_flow(flow_path, width, height);
  const bool skipped = field.has_value();
  if (skipped) {
    ++outcome.pairs_skipped;
    session_holds_from_ = false;  // the next computed pair starts the stream afresh
  } else {
    field = compute(from, to);
    flow::write_flow(*field, flow_path);
    ++outcome.pairs_written;
  }
  // A kept flow keeps its rendering too, unless that one is missing or cut short.
  const bool write_png = settings_.viz == VizMode::png && !(skipped && complete_png(png_path, width, height));
  render(*field, from, write_png);

  // A row's index is the pair's position in the whole input, so the ranges' indexes add up.
  const std::int64_t index = rows_ + (settings_.frames ? settings_.frames->first : 0);
  index_.add({index, from.number, to.number, from.pts_ns, to.pts_ns, file, from.source, to.source});
  ++rows_;
  progress_.pair_done();
}

flow::FlowField Conversion::compute(const Frame& from, const Frame& to) {
  try {
    // --padding bottom: padded here to multiples of 16 as eval pads the benchmark (the session
    // then pads nothing) and the flow cropped back; otherwise the session pads them itself.
    std::optional<eval::Padding> padding;
    if (settings_.padding) padding = eval::reference_padding(to.pixels.cols, to.pixels.rows, *settings_.padding);
    const auto prepared = [&](const Frame& f) {
      Frame p = f;
      if (padding) p.pixels = eval::pad_image(f.pixels, *padding);
      return p;
    };
    // After a skipped pair the session's last frame is not this pair's first: start the
    // stream again from it, so the result is the same as in an uninterrupted run.
    if (!session_holds_from_) {
      session_.reset();
      session_.push(view_of(prepared(from)));
    }
    auto field = session_.push(view_of(prepared(to)));
    session_holds_from_ = true;
    if (!field) throw std::logic_error("the session returned no flow for a pair");
    return padding ? eval::crop_flow(*field, *padding) : std::move(*field);
  } catch (const std::invalid_argument& e) {
    throw InputError(kExitDataError, describe(from) + " -> " + describe(to) + ": " + e.what());
  }
}

// The frame's pixels as RGB, whatever order they are held in.
flow::RgbImage rgb_of(const Frame& frame) {
  const int w = frame.pixels.cols, h = frame.pixels.rows;
  flow::RgbImage image{w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h)};
  cv::Mat rgb(h, w, CV_8UC3, image.rgb.data());
  if (frame.data_order == model::ChannelOrder::bgr) {
    cv::cvtColor(frame.pixels, rgb, cv::COLOR_BGR2RGB);
  } else {
    frame.pixels.copyTo(rgb);
  }
  return image;
}

void Conversion::render(const flow::FlowField& field, const Frame& from, bool write_png) {
  if (settings_.viz == VizMode::none || (settings_.viz == VizMode::png && !write_png)) return;
  flow::VisualizeOptions options;
  options.max_flow = settings_.max_flow;
  flow::RgbImage image = flow::visualize_flow(field, options).image;
  if (settings_.viz_look == VizLook::overlay) image = flow::blend(rgb_of(from), image, flow::kOverlayAlpha);
  if (settings_.viz == VizMode::png) {
    flow::write_rgb_png(image, dir_ / "viz" / (from.output_stem + ".png"));
    return;
  }
  if (!video_) {
    pipeline::FrameRate rate = frames_->frame_rate();
    if (input_.kind != InputKind::video && settings_.image_rate) rate = *settings_.image_rate;
    video_ = std::make_unique<pipeline::VideoEncoder>(dir_ / range_name("viz", ".mp4", settings_.frames), image.width,
                                                      image.height, rate.known() ? rate : kImageSequenceRate);
  }
  video_->write(image);
}

void Conversion::finish_outputs() {
  if (video_) video_->finish();
  index_.write();
}

}  // namespace

std::string FrameRange::suffix() const {
  return std::to_string(first) + "-" + (end ? std::to_string(*end) : std::string("end"));
}

InputOutcome convert_input(const InputSpec& input, model::FlowSession& session, const ConvertSettings& settings,
                           Progress& progress) {
  InputOutcome outcome;
  outcome.output = settings.output_dir / input.output_name;
  const auto started = std::chrono::steady_clock::now();
  Conversion conversion(input, session, settings, progress);
  const auto record = [&](InputError error) {
    if (!outcome.error) outcome.error = std::move(error);
  };
  try {
    conversion.run(outcome);
    if (outcome.interrupted) {
      if (conversion.has_rows()) conversion.write_index();
    } else {
      conversion.finish_outputs();
    }
  } catch (const InputError& e) {
    record(e);
  } catch (const flow::FlowFileError& e) {
    record(InputError(exit_code_for(e), e.what()));
  } catch (const pipeline::PipelineError& e) {
    record(to_input_error(e));
  } catch (const fs::filesystem_error& e) {
    record(InputError(kExitCantCreate, e.path1().string() + ": " + e.code().message()));
  } catch (const cv::Exception& e) {
    record(InputError(kExitDataError, input.label + ": " + e.what()));
  } catch (const std::exception& e) {
    record(InputError(kExitFailure, input.label + ": " + e.what()));
  }
  // After a failure the index still describes the flow files this run wrote.
  if (outcome.error && conversion.has_rows()) {
    try {
      conversion.write_index();
    } catch (const std::exception&) {
      // The failure already recorded is the one to report; this one has the same cause.
    }
  }
  progress.end();
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return outcome;
}

}  // namespace neuflow::cli
