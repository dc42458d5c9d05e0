#include "neuflow/eval/prediction_files.hpp"

#include <string>
#include <system_error>

#include "neuflow/eval/errors.hpp"
#include "neuflow/flow/flow_io.hpp"

namespace neuflow::eval {

std::filesystem::path find_prediction(const std::filesystem::path& dir, const Pair& pair) {
  const std::filesystem::path stem = dir / pair.key;
  std::error_code ec;
  for (const char* extension : {".flo", ".png", ".npy"}) {
    std::filesystem::path candidate = stem;
    candidate += extension;
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  }
  throw EvalError(EvalError::Kind::missing_input, stem.string() + ".{flo,png,npy}: no prediction for " +
                                                      pair.image0.string() +
                                                      " (expected DIR/<first image's path "
                                                      "in the dataset, without extension> + .flo, .png or .npy)");
}

flow::FlowField PredictionReader::operator()(const EvalSet&, const Pair& pair) const {
  return flow::read_flow(find_prediction(dir_, pair));
}

}  // namespace neuflow::eval
