// `neuflow inspect CKPT`: what a checkpoint holds and whether it is NeuFlow-V2.
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "commands.hpp"
#include "neuflow/model/architecture.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace neuflow::cli {

namespace {

std::string with_commas(int64_t value) {
  std::string digits = std::to_string(value < 0 ? -value : value);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return value < 0 ? "-" + out : out;
}

std::string shape_text(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

std::string wrapper_text(const std::string& wrapper) {
  if (wrapper == "bare") return "bare state dict";
  return "{'" + wrapper + "': state_dict}";
}

void run_inspect(const std::string& path, bool list) {
  model::Checkpoint checkpoint;
  try {
    checkpoint = model::load_checkpoint(path);
  } catch (const model::CheckpointError& e) {
    throw CommandError(exit_code_for(e), std::string("inspect: ") + e.what());
  }

  std::map<std::string, int> dtypes;
  for (const auto& [key, tensor] : checkpoint.tensors) ++dtypes[tensor.dtype];
  std::string dtype_line;
  for (const auto& [dtype, count] : dtypes) {
    if (!dtype_line.empty()) dtype_line += ", ";
    dtype_line += dtype + " (" + std::to_string(count) + (count == 1 ? " tensor)" : " tensors)");
  }
  const model::ParameterCount count = model::count_parameters(checkpoint);
  const auto mismatch = model::find_architecture_mismatch(checkpoint);

  std::printf("file:         %s\n", checkpoint.path.c_str());
  std::printf("format:       %s\n", checkpoint.container.c_str());
  std::printf("state dict:   %s%s\n", wrapper_text(checkpoint.wrapper).c_str(),
              checkpoint.stripped_module_prefix ? ", 'module.' prefix stripped" : "");
  std::printf("dtypes:       %s\n", dtype_line.empty() ? "-" : dtype_line.c_str());
  std::printf("tensors:      %zu\n", checkpoint.keys.size());
  std::printf("parameters:   %s trainable (+ %s in BatchNorm running statistics/counters)\n",
              with_commas(count.parameters).c_str(), with_commas(count.buffers).c_str());
  if (mismatch) {
    std::printf("architecture: not NeuFlow-V2: %s\n", mismatch->c_str());
  } else {
    std::printf("architecture: NeuFlow-V2 (all %zu tensors match)\n", model::neuflow_v2_parameters().size());
  }

  if (list) {
    std::size_t width = 0;
    for (const auto& key : checkpoint.keys) width = std::max(width, key.size());
    std::printf("\n");
    for (const auto& key : checkpoint.keys) {
      const auto& tensor = checkpoint.tensors.at(key);
      std::printf("%-*s  %-18s %s\n", static_cast<int>(width), key.c_str(), shape_text(tensor.shape).c_str(),
                  tensor.dtype.c_str());
    }
  }
  std::fflush(stdout);

  if (mismatch) {
    throw CommandError(kExitDataError, "inspect: '" + path + "' is not a NeuFlow-V2 checkpoint: " + *mismatch);
  }
}

}  // namespace

void register_inspect(CLI::App& app) {
  auto* sub = app.add_subcommand("inspect", "Describe a PyTorch checkpoint (.pth) and check it against NeuFlow-V2");
  auto path = std::make_shared<std::string>();
  auto list = std::make_shared<bool>(false);
  sub->add_option("checkpoint", *path, "PyTorch checkpoint (.pth, zip format)")->required();
  sub->add_flag("--list", *list, "Print every tensor's key, shape and dtype");
  sub->footer(
      "Exit status: 0 when the checkpoint is NeuFlow-V2, 65 when it is malformed or another "
      "network, 66 when the file is missing or unreadable. Nothing in the file is executed.");
  sub->callback([path, list] { run_inspect(*path, *list); });
}

}  // namespace neuflow::cli
