#pragma once
// The flow-gt fixtures arranged into each benchmark's folder layout inside a scratch folder
// (symbolic links, nothing copied; scratch folders: support/temp_dir.hpp), plus prediction
// files derived from the ground truth.
#include <filesystem>
#include <functional>
#include <string>

#include "neuflow/eval/layouts.hpp"
#include "neuflow/flow/flow_field.hpp"

namespace neuflow::eval::test {

// A symbolic link at `link` (parents created) to `target`.
void link_file(const std::filesystem::path& target, const std::filesystem::path& link);

// Each builds ROOT from flow_gt (the fixtures' flow-gt folder) and returns ROOT:
//   ROOT/training/{clean,final}/{alley_1,market_5}/frame_000N.png, ROOT/training/flow/<scene>/frame_000N.flo
//   (alley_1: frame_0002 → 0003, market_5: frame_0009 → 0010)
std::filesystem::path arrange_sintel(const std::filesystem::path& flow_gt, const std::filesystem::path& root);
//   ROOT/training/image_2/000000_1{0,1}.png, ROOT/training/flow_occ/000000_10.png
std::filesystem::path arrange_kitti(const std::filesystem::path& flow_gt, const std::filesystem::path& root);
//   ROOT/other-data/{RubberWhale,Urban2}/frame1{0,1}.png, ROOT/other-gt-flow/<seq>/flow10.flo
std::filesystem::path arrange_middlebury(const std::filesystem::path& flow_gt, const std::filesystem::path& root);
//   ROOT/data/0000{1,2}_img{1,2}.ppm, ROOT/data/0000{1,2}_flow.flo (the one fixture pair twice)
std::filesystem::path arrange_chairs(const std::filesystem::path& flow_gt, const std::filesystem::path& root);

// Writes DIR/<key><extension> for every pair of the set: its ground truth passed through
// `transform`.
void write_predictions(const EvalSet& set, const std::filesystem::path& dir, const std::string& extension,
                       const std::function<void(flow::FlowField&)>& transform);

// Adds (du, dv) to every vector.
std::function<void(flow::FlowField&)> offset_by(float du, float dv);

}  // namespace neuflow::eval::test
