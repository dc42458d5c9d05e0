#pragma once
// Scoring one set of pairs: each pair's predicted flow against its ground truth, combined
// by the set's Aggregation, overall and per sequence.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "neuflow/eval/layouts.hpp"
#include "neuflow/eval/scoring.hpp"
#include "neuflow/flow/flow_field.hpp"

namespace neuflow::eval {

// The predicted flow for a pair, at its ground truth's size (ModelPredictor, PredictionReader).
using FlowSource = std::function<flow::FlowField(const EvalSet&, const Pair&)>;

struct SequenceResult {
  std::string name;
  Summary summary;
};

struct SetResult {
  std::string name;
  Dataset dataset = Dataset::sintel;
  Aggregation aggregation = Aggregation::pooled_pixels;
  Summary summary;
  std::vector<SequenceResult> sequences;  // in the order the sequences first appear
};

struct EvalProgress {
  const EvalSet& set;
  std::size_t done;   // pairs scored so far
  std::size_t total;  // pairs that will be scored
  const Summary& so_far;
  double elapsed_seconds;  // since the set's first pair started
};

struct EvaluateOptions {
  std::size_t max_pairs = 0;                          // score only the first N pairs of the set; 0: all
  std::function<void(const EvalProgress&)> progress;  // after every pair, if set
  // Every pair's prediction and ground truth once scored (--save-viz), if set.
  std::function<void(const EvalSet&, const Pair&, const flow::FlowField& predicted,
                     const flow::FlowField& ground_truth)>
      on_pair;
};

// Throws what the source and the ground-truth reader throw (EvalError, flow::FlowFileError,
// model errors), and EvalError (malformed_input) when a prediction's size differs from its
// ground truth's.
SetResult evaluate_set(const EvalSet& set, const FlowSource& source, const EvaluateOptions& options = {});

}  // namespace neuflow::eval
