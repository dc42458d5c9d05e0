#include "neuflow/eval/model_predictor.hpp"

#include <opencv2/imgcodecs.hpp>

#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "common/image_header.hpp"
#include "neuflow/eval/errors.hpp"

namespace neuflow::eval {

namespace {

model::SessionOptions session_options(model::SessionOptions s) {
  // 0 × 0: the session runs at the input's own size; we hand it sizes that are already
  // multiples of 16, so its own (always centred) padding stays zero.
  s.model_width = s.model_height = 0;
  return s;
}

std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

}  // namespace

cv::Mat read_bgr_image(const std::filesystem::path& path, const model::FlowSession* session) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw EvalError(EvalError::Kind::missing_input, path.string() + ": no such image file");
  }
  if (session != nullptr) {
    const auto check = [&](int w, int h) { return session->frame_problem(w, h); };
    if (auto problem = cli::image_too_large(path, check)) throw EvalError(EvalError::Kind::malformed_input, *problem);
  }
  // IMREAD_COLOR: 8-bit BGR whatever the file holds (grey replicated, 16 bits scaled down).
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  if (image.empty()) {
    throw EvalError(EvalError::Kind::malformed_input, path.string() + ": not an image OpenCV can decode");
  }
  return image;
}

ModelPredictor::ModelPredictor(std::shared_ptr<const model::FlowModel> model, const model::SessionOptions& options)
    : session_(std::move(model), session_options(options)) {}

flow::FlowField ModelPredictor::predict(const cv::Mat& bgr0, const cv::Mat& bgr1, PadMode mode) {
  if (bgr0.size() != bgr1.size() || bgr0.type() != CV_8UC3 || bgr1.type() != CV_8UC3) {
    throw EvalError(EvalError::Kind::malformed_input, "the two images of a pair must be 8-bit BGR of one size, got " +
                                                          size_text(bgr0) + " and " + size_text(bgr1));
  }
  const Padding padding = reference_padding(bgr0.cols, bgr0.rows, mode);
  const cv::Mat padded0 = pad_image(bgr0, padding), padded1 = pad_image(bgr1, padding);
  const auto view = [](const cv::Mat& m) {
    return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), model::ChannelOrder::bgr};
  };
  try {
    return crop_flow(session_.compute(view(padded0), view(padded1)), padding);
  } catch (const std::invalid_argument& e) {
    throw EvalError(EvalError::Kind::malformed_input,
                    "cannot run the network on a " + size_text(bgr0) + " pair: " + e.what());
  }
}

flow::FlowField ModelPredictor::operator()(const EvalSet& set, const Pair& pair) {
  const cv::Mat image0 = read_bgr_image(pair.image0, &session_), image1 = read_bgr_image(pair.image1, &session_);
  if (image0.size() != image1.size()) {
    throw EvalError(EvalError::Kind::malformed_input, pair.image0.string() + " is " + size_text(image0) + " but " +
                                                          pair.image1.string() + " is " + size_text(image1));
  }
  return predict(image0, image1, set.pad_mode);
}

}  // namespace neuflow::eval
