#include "neuflow/model/flow_model.hpp"

#include <map>
#include <mutex>

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
      throw CheckpointError(CheckpointError::Kind::kFormat,
                            checkpoint_path.string() + ": not a NeuFlow-V2 checkpoint: " + *mismatch);
    }
    return std::make_unique<const NetworkWeights>(build_network_weights(checkpoint));
  }();  // the checkpoint's own copy of the weights is released here
  return std::shared_ptr<const FlowModel>(new FlowModel(checkpoint_path, std::move(weights)));
}

std::shared_ptr<const FlowModel> FlowModel::load_shared(const std::filesystem::path& checkpoint_path) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const FlowModel>> loaded;
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(checkpoint_path, ec);
  const std::string key = ec ? checkpoint_path.string() : canonical.string();
  // Loading happens under the lock so that two elements starting together load once.
  const std::lock_guard lock(mutex);
  if (auto model = loaded[key].lock()) return model;
  auto model = load(checkpoint_path);
  loaded[key] = model;
  return model;
}

}  // namespace neuflow::model
