#include "neuflow/eval/evaluate.hpp"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <string>

#include "neuflow/eval/errors.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/metrics.hpp"

namespace neuflow::eval {

SetResult evaluate_set(const EvalSet& set, const FlowSource& source, const EvaluateOptions& options) {
  const std::size_t total = options.max_pairs == 0 ? set.pairs.size() : std::min(options.max_pairs, set.pairs.size());
  const auto start = std::chrono::steady_clock::now();
  ScoreAccumulator overall(set.aggregation);
  std::vector<std::string> sequence_names;
  std::vector<ScoreAccumulator> sequences;

  for (std::size_t i = 0; i < total; ++i) {
    const Pair& pair = set.pairs[i];
    const flow::FlowField ground_truth = flow::read_flow(pair.ground_truth);
    const flow::FlowField predicted = source(set, pair);
    if (predicted.width != ground_truth.width || predicted.height != ground_truth.height) {
      throw EvalError(EvalError::Kind::malformed_input,
                      "the flow for " + pair.key + " is " + std::to_string(predicted.width) + "x" +
                          std::to_string(predicted.height) + " but its ground truth " + pair.ground_truth.string() +
                          " is " + std::to_string(ground_truth.width) + "x" + std::to_string(ground_truth.height));
    }
    const flow::FlowMetrics metrics = flow::compute_metrics(predicted, ground_truth);
    overall.add(metrics);
    if (options.on_pair) options.on_pair(set, pair, predicted, ground_truth);
    // Pairs of a sequence are adjacent, so the last name is the one to check first.
    auto it = std::find(sequence_names.rbegin(), sequence_names.rend(), pair.sequence);
    if (it == sequence_names.rend()) {
      sequence_names.push_back(pair.sequence);
      sequences.emplace_back(set.aggregation);
      sequences.back().add(metrics);
    } else {
      sequences[static_cast<std::size_t>(std::distance(it, sequence_names.rend())) - 1].add(metrics);
    }
    if (options.progress) {
      const Summary so_far = overall.summary();
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      options.progress(EvalProgress{set, i + 1, total, so_far, elapsed});
    }
  }

  SetResult result;
  result.name = set.name;
  result.dataset = set.dataset;
  result.aggregation = set.aggregation;
  result.summary = overall.summary();
  for (std::size_t s = 0; s < sequences.size(); ++s)
    result.sequences.push_back({sequence_names[s], sequences[s].summary()});
  return result;
}

}  // namespace neuflow::eval
