#pragma once
// The standard benchmarks' folder layouts, turned into lists of image pairs with their ground
// truth:
//   Sintel      ROOT/training/{clean,final}/<scene>/frame_NNNN.png, ROOT/training/flow/<scene>/frame_NNNN.flo
//               (each .flo pairs the image of the same name with the next image of its scene)
//   KITTI-2015  ROOT/training/image_2/NNNNNN_10.png, NNNNNN_11.png, ROOT/training/flow_occ/NNNNNN_10.png
//   Middlebury  ROOT/other-data/<seq>/frame10.png, frame11.png, ROOT/other-gt-flow/<seq>/flow10.flo
//   FlyingChairs ROOT/data/NNNNN_img1.ppm, NNNNN_img2.ppm, NNNNN_flow.flo, and when
//               ROOT/FlyingChairs_train_val.txt exists, only its validation pairs (label 2)
// For Sintel and KITTI, ROOT may also be the training/ folder itself; for FlyingChairs, the
// data/ folder.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "neuflow/eval/padding.hpp"

namespace neuflow::eval {

enum class Dataset { sintel, kitti, middlebury, chairs };

std::optional<Dataset> parse_dataset(std::string_view name);
std::string_view to_string(Dataset dataset);

// How per-pair results combine into a set's numbers, as the reference evaluation does
// (RAFT's and NeuFlow-V2's evaluate.py).
enum class Aggregation {
  // EPE and 1/3/5 px rates over all valid pixels of all pairs together
  // (validate_sintel, validate_chairs; used for Middlebury too).
  pooled_pixels,
  // EPE: the mean of each image's EPE over its valid pixels; Fl-all and the 1/3/5 px rates
  // over all valid pixels of all pairs together (validate_kitti).
  mean_of_images,
};

struct Pair {
  std::filesystem::path image0, image1, ground_truth;
  // Sintel scene or Middlebury sequence; for KITTI and FlyingChairs, which have no
  // sequences, the pair's own id (000000, 00001).
  std::string sequence;
  // The first image's path relative to the set's root, without extension, with '/'
  // (clean/alley_1/frame_0001, image_2/000000_10): names the pair and its prediction file.
  std::string key;
};

struct EvalSet {
  std::string name;  // sintel-clean, sintel-final, kitti, middlebury, chairs, chairs-val
  Dataset dataset = Dataset::sintel;
  PadMode pad_mode = PadMode::centred;
  Aggregation aggregation = Aggregation::pooled_pixels;
  std::filesystem::path root;  // what the keys are relative to
  std::vector<Pair> pairs;
};

enum class SintelPass { clean, final, both };

struct LayoutOptions {
  SintelPass sintel_pass = SintelPass::both;
};

// The sets to evaluate under root (two for Sintel with both passes, else one), pairs in
// sorted order. Every listed file is checked to exist. Throws EvalError: missing_input when
// root, a layout folder or a pair's image is absent or the layout holds no pair (the message
// says what was looked for), malformed_input for an unusable split file.
std::vector<EvalSet> discover_sets(Dataset dataset, const std::filesystem::path& root,
                                   const LayoutOptions& options = {});

}  // namespace neuflow::eval
