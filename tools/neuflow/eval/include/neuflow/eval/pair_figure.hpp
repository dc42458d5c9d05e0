#pragma once
// Pictures of an evaluation, because people would rather look than read:
// - one PNG per pair: the prediction, the ground truth and the end-point-error map side by
//   side, each labelled; the two flows on one colour scale (the ground truth's largest valid
//   vector), its key drawn on the ground truth; the error as a colour map with its scale bar
//   (flow/figures.hpp) and the pair's EPE in its label; pixels the ground truth does not score
//   black in the flows, grey in the error;
// - an SVG bar chart of the EPE per sequence.
#include <filesystem>
#include <vector>

#include "neuflow/eval/evaluate.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/visualize.hpp"

namespace neuflow::eval {

// The three panels, each at the flows' size, left to right, with a 4-pixel grey gap.
// Throws std::invalid_argument when the two fields differ in size.
flow::RgbImage pair_figure(const flow::FlowField& predicted, const flow::FlowField& ground_truth);

// Throws flow::FlowFileError (write_failed) naming the file when it cannot be written.
void write_pair_figure(const flow::FlowField& predicted, const flow::FlowField& ground_truth,
                       const std::filesystem::path& path);

// One bar per sequence of each set (EPE), labelled with its name and value; sets one after
// the other, each titled. Throws std::runtime_error naming the file when it cannot be written.
void write_epe_plot(const std::vector<SetResult>& results, const std::filesystem::path& path);

}  // namespace neuflow::eval
