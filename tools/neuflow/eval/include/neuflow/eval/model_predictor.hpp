#pragma once
// Flow for a benchmark pair from a NeuFlow-V2 model, prepared as the reference evaluation
// prepares it: the images edge-padded to multiples of 16 by the set's PadMode (so the core
// runs at exactly that size and pads nothing itself), the flow cropped back.
#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

#include "neuflow/eval/layouts.hpp"
#include "neuflow/eval/padding.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace neuflow::eval {

// An image as 8-bit BGR (grey and 16-bit images converted). Throws EvalError: missing_input
// when the file is absent, malformed_input when OpenCV cannot decode it, or when `session`
// could not take frames of the size its header states (checked before decoding).
cv::Mat read_bgr_image(const std::filesystem::path& path, const model::FlowSession* session = nullptr);

class ModelPredictor {
 public:
  // The options' model size is ignored: the pairs are padded here as the reference pads them.
  ModelPredictor(std::shared_ptr<const model::FlowModel> model, const model::SessionOptions& options);

  // Flow from image0 to image1 (8-bit BGR, same size) at their size. Throws EvalError
  // (malformed_input) when the sizes differ or the network cannot take them.
  flow::FlowField predict(const cv::Mat& bgr0, const cv::Mat& bgr1, PadMode mode);

  // The pair's images read from disk, then predict() with the set's padding.
  flow::FlowField operator()(const EvalSet& set, const Pair& pair);

  const model::FlowSession& session() const { return session_; }

 private:
  model::FlowSession session_;
};

}  // namespace neuflow::eval
