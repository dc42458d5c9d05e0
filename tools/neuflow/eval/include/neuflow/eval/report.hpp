#pragma once
// The results for people (a table) and for scripts (JSON).
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "neuflow/eval/evaluate.hpp"
#include "neuflow/eval/layouts.hpp"
#include "neuflow/model/flow_session.hpp"

namespace neuflow::eval {

// What was evaluated and how, echoed into the JSON so a result file explains itself.
struct RunDescription {
  Dataset dataset = Dataset::sintel;
  std::filesystem::path root;
  std::filesystem::path model;        // the checkpoint, or empty when scoring predictions
  std::filesystem::path predictions;  // the predictions folder, or empty when running a model
  model::Iterations iterations;
  model::ChannelOrder network_order = model::ChannelOrder::rgb;
  std::size_t max_pairs = 0;  // 0: all pairs
};

// One row per set (set, pairs, EPE, Fl-all when a KITTI set is among them, <1/3/5 px in %),
// and with per_sequence one indented row per sequence under it.
std::string format_table(const std::vector<SetResult>& results, bool per_sequence);

// One JSON object: the run's description and "results", one object per set with "set",
// "pairs", "valid_pixels", "epe", "fl_all", "within_1px", "within_3px", "within_5px" (ratios as
// fractions; null where not available) and "epe_aggregation" ("pixels" or "images"), plus
// "sequences" (the same fields, "sequence" for "set") with per_sequence.
std::string format_json(const RunDescription& run, const std::vector<SetResult>& results, bool per_sequence);

}  // namespace neuflow::eval
