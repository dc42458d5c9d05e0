#pragma once
// A loaded NeuFlow-V2 model: the checkpoint's weights, validated against the architecture
// and prepared for inference (BatchNorms folded). Read-only after load, so one instance is
// shared by any number of sessions and threads.
#include <filesystem>
#include <memory>
#include <string>

namespace neuflow::model {

struct NetworkWeights;

class FlowModel {
 public:
  // Throws CheckpointError (see checkpoint.hpp) naming the file and the problem.
  static std::shared_ptr<const FlowModel> load(const std::filesystem::path& checkpoint);

  // The same, but one instance per checkpoint file in the process: while any user holds the
  // model, loading the same file again returns it instead of a second copy.
  static std::shared_ptr<const FlowModel> load_shared(const std::filesystem::path& checkpoint);

  ~FlowModel();
  FlowModel(const FlowModel&) = delete;
  FlowModel& operator=(const FlowModel&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const NetworkWeights& weights() const { return *weights_; }

 private:
  FlowModel(std::filesystem::path path, std::unique_ptr<const NetworkWeights> weights);
  std::filesystem::path path_;
  std::unique_ptr<const NetworkWeights> weights_;
};

}  // namespace neuflow::model
