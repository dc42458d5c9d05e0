#pragma once
// Precomputed predictions, one flow file per pair: DIR/<key>.flo, .png (KITTI 16-bit) or
// .npy, where <key> is the pair's key (its first image's path relative to the set's root,
// without extension), e.g. DIR/clean/alley_1/frame_0001.flo for Sintel, DIR/image_2/000000_10.png
// for KITTI, DIR/other-data/RubberWhale/frame10.flo for Middlebury, DIR/00001_img1.flo for
// FlyingChairs.
#include <filesystem>
#include <utility>

#include "neuflow/eval/layouts.hpp"
#include "neuflow/flow/flow_field.hpp"

namespace neuflow::eval {

// The pair's prediction file, trying .flo, .png, .npy in that order. Throws EvalError
// (missing_input) naming the names tried.
std::filesystem::path find_prediction(const std::filesystem::path& dir, const Pair& pair);

class PredictionReader {
 public:
  explicit PredictionReader(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // Throws EvalError or flow::FlowFileError.
  flow::FlowField operator()(const EvalSet& set, const Pair& pair) const;

 private:
  std::filesystem::path dir_;
};

}  // namespace neuflow::eval
