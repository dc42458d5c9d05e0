#include "convert/frames.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "common/exit_codes.hpp"
#include "convert/natural_sort.hpp"
#include "neuflow/pipeline/pipeline_error.hpp"
#include "neuflow/pipeline/video_decoder.hpp"

namespace neuflow::cli {

namespace fs = std::filesystem;

namespace {

struct ImageFile {
  fs::path path;
  std::string output_stem;
};

class ImageSequence final : public FrameSource {
 public:
  ImageSequence(std::vector<ImageFile> files, FrameSizeCheck check)
      : files_(std::move(files)), times_(capture_times_ns(stems())), check_(std::move(check)) {}

  std::optional<Frame> next() override {
    if (next_ >= files_.size()) return std::nullopt;
    const ImageFile& file = files_[next_];
    std::error_code ec;
    if (!fs::is_regular_file(file.path, ec))
      throw InputError(kExitNoInput, file.path.string() + ": no such image file");
    if (check_) {
      if (auto problem = image_too_large(file.path, check_)) throw InputError(kExitDataError, *problem);
    }
    Frame frame;
    frame.pixels = cv::imread(file.path.string(), cv::IMREAD_COLOR);
    if (frame.pixels.empty()) {
      throw InputError(kExitDataError, file.path.string() + ": not an image OpenCV can decode");
    }
    frame.data_order = model::ChannelOrder::bgr;
    frame.number = static_cast<std::int64_t>(next_);
    frame.source = file.path.filename().string();
    frame.output_stem = file.output_stem;
    if (!times_.empty()) frame.pts_ns = times_[next_];
    ++next_;
    return frame;
  }

  std::optional<std::int64_t> frame_count() const override { return static_cast<std::int64_t>(files_.size()); }
  pipeline::FrameRate frame_rate() const override { return rate_from_timestamps(stems()); }

 private:
  std::vector<std::string> stems() const {
    std::vector<std::string> stems;
    stems.reserve(files_.size());
    for (const auto& file : files_) stems.push_back(file.path.stem().string());
    return stems;
  }

  std::vector<ImageFile> files_;
  std::vector<std::int64_t> times_;  // the names' capture times, or none
  FrameSizeCheck check_;
  std::size_t next_ = 0;
};

class VideoFrames final : public FrameSource {
 public:
  explicit VideoFrames(const std::string& source) try : decoder_(source) {
  } catch (const pipeline::PipelineError& e) {
    throw to_input_error(e);
  }

  std::optional<Frame> next() override {
    std::optional<pipeline::RgbFrame> decoded;
    try {
      decoded = decoder_.next();
    } catch (const pipeline::PipelineError& e) {
      throw to_input_error(e);
    }
    if (!decoded) return std::nullopt;
    Frame frame;
    // The decoder's rows are packed, so the Mat can wrap them before the one copy it keeps.
    frame.pixels = cv::Mat(decoded->height, decoded->width, CV_8UC3, decoded->rgb.data()).clone();
    frame.data_order = model::ChannelOrder::rgb;
    frame.number = decoded->number;
    frame.pts_ns = decoded->pts_ns;
    char stem[32];
    std::snprintf(stem, sizeof stem, "frame_%06lld", static_cast<long long>(decoded->number));
    frame.output_stem = stem;
    return frame;
  }

  std::optional<std::int64_t> frame_count() const override { return decoder_.frame_count_estimate(); }
  pipeline::FrameRate frame_rate() const override { return decoder_.frame_rate(); }

 private:
  pipeline::VideoDecoder decoder_;
};

// Output stems for a list of images: the stem, unless another image shares it (a.png and
// a.jpg), in which case the whole file name keeps the outputs apart.
std::vector<ImageFile> name_images(const std::vector<fs::path>& paths) {
  std::map<std::string, int> stems;
  for (const auto& p : paths) ++stems[p.stem().string()];
  std::vector<ImageFile> files;
  files.reserve(paths.size());
  for (const auto& p : paths) {
    files.push_back({p, stems[p.stem().string()] > 1 ? p.filename().string() : p.stem().string()});
  }
  return files;
}

std::vector<fs::path> list_images(const fs::path& folder) {
  std::vector<fs::path> images;
  std::error_code ec;
  fs::directory_iterator it(folder, ec), end;
  if (ec) throw InputError(kExitNoInput, folder.string() + ": cannot list the folder: " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) throw InputError(kExitNoInput, folder.string() + ": cannot list the folder: " + ec.message());
    std::error_code file_ec;
    if (it->is_regular_file(file_ec) && has_image_extension(it->path().filename().string())) {
      images.push_back(it->path());
    }
  }
  std::sort(images.begin(), images.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return images;
}

}  // namespace

std::vector<std::int64_t> capture_times_ns(const std::vector<std::string>& stems) {
  if (stems.empty()) return {};
  const std::size_t digits = stems.front().size();
  std::int64_t ns_per_tick = 0;
  switch (digits) {
    case 10: ns_per_tick = 1'000'000'000; break;
    case 13: ns_per_tick = 1'000'000; break;
    case 16: ns_per_tick = 1'000; break;
    case 19: ns_per_tick = 1; break;
    default: return {};
  }
  std::vector<std::int64_t> times;
  for (const std::string& stem : stems) {
    if (stem.size() != digits ||
        !std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) {
      return {};
    }
    const std::uint64_t t = std::stoull(stem);
    // 19 digits fit an int64 only up to 9223372036854775807 ns (the year 2262).
    if (t > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / ns_per_tick)) return {};
    const std::int64_t ns = static_cast<std::int64_t>(t) * ns_per_tick;
    if (!times.empty() && ns <= times.back()) return {};
    times.push_back(ns);
  }
  return times;
}

pipeline::FrameRate rate_from_timestamps(const std::vector<std::string>& stems) {
  const std::vector<std::int64_t> times = capture_times_ns(stems);
  if (times.size() < 2) return {};
  const double seconds = static_cast<double>(times.back() - times.front()) * 1e-9;
  const double fps = static_cast<double>(times.size() - 1) / seconds;
  if (!(fps > 0) || fps > 1000) return {};
  return {static_cast<int>(std::lround(fps * 1000)), 1000};
}

std::unique_ptr<FrameSource> open_frames(const InputSpec& input, FrameSizeCheck check) {
  if (input.rejected) throw *input.rejected;
  switch (input.kind) {
    case InputKind::image_pair: {
      // The pair's folder (a_b/) already names both images; its one flow is flow.<ext>, so a
      // KITTI .png flow beside them is not taken for the first image, whose name it had.
      auto files = name_images({fs::path(input.paths[0]), fs::path(input.paths[1])});
      files[0].output_stem = "flow";
      return std::make_unique<ImageSequence>(std::move(files), std::move(check));
    }
    case InputKind::image_folder: {
      auto images = list_images(input.paths[0]);
      if (images.empty()) {
        throw InputError(kExitNoInput, input.paths[0] + ": no image files (.png, .jpg, ...) in the folder");
      }
      return std::make_unique<ImageSequence>(name_images(images), std::move(check));
    }
    case InputKind::video: return std::make_unique<VideoFrames>(input.paths[0]);
  }
  throw InputError(kExitFailure, input.label + ": unknown kind of input");
}

}  // namespace neuflow::cli
