#pragma once
// The first frames of the fixture camera sequence (shared/fixtures/frames), resized for a test,
// as 8-bit BGR images, and a session's view of one.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "neuflow/model/image_view.hpp"

namespace neuflow::test {

// `count` frames of `folder` in name order, each resized to `size` (INTER_AREA); throws when
// the folder holds fewer.
inline std::vector<cv::Mat> camera_frames(const std::filesystem::path& folder, std::size_t count, cv::Size size) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(folder)) {
    if (e.path().extension() == ".jpg") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (files.size() < count) {
    throw std::runtime_error(folder.string() + ": expected at least " + std::to_string(count) + " .jpg frames");
  }
  std::vector<cv::Mat> frames;
  for (std::size_t i = 0; i < count; ++i) {
    cv::Mat full = cv::imread(files[i].string(), cv::IMREAD_COLOR), small;
    cv::resize(full, small, size, 0, 0, cv::INTER_AREA);
    frames.push_back(small);
  }
  return frames;
}

inline model::ImageView bgr_view(const cv::Mat& m) {
  return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), model::ChannelOrder::bgr};
}

}  // namespace neuflow::test
