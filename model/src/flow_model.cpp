#include "neuflow/model/flow_model.hpp"

#include "neuflow/model/architecture.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "weights.hpp"

namespace neuflow::model {

FlowModel::FlowModel(std::filesystem::path path, std::unique_ptr<const NetworkWeights> weights)
    : path_(std::move(path)), weights_(std::move(weights)) {}

FlowModel::~FlowModel() = default;

std::shared_ptr<const FlowModel> FlowModel::load(const std::filesystem::path& checkpoint_path) {
  auto weights = [&] {
    const Checkpoint checkpoint = load_checkpoint(checkpoint_path);
    if (auto mismatch = find_architecture_mismatch(checkpoint)) {
      throw CheckpointError(CheckpointError::Kind::kFormat, checkpoint_path.string() + ": not a NeuFlow-V2 checkpoint: " + *mismatch);
    }
    return std::make_unique<const NetworkWeights>(build_network_weights(checkpoint));
  }();  // the checkpoint's own copy of the weights is released here
  return std::shared_ptr<const FlowModel>(new FlowModel(checkpoint_path, std::move(weights)));
}

}  // namespace neuflow::model
