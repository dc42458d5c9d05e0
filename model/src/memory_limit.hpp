#pragma once
// How much memory a plan for one model size takes, known before the plan is made, and the
// limit it must fit (SessionOptions::max_memory_mb): a frame size that would exhaust the
// machine is refused with a sentence naming the size, the need and the limit, instead of
// swapping or being killed.
#include <cstddef>
#include <optional>
#include <string>

#include "neuflow/model/session_settings.hpp"
#include "weights.hpp"

namespace neuflow::model {

// Bytes, from the network graph's tensors at that model size: the transient ones placed by
// their live ranges, with a third more for the backends' own layouts (blocked channels) and the
// ops' scratch; the persistent ones; the frames' tensors in every slot; the flow a pass returns.
// The weights and the Winograd filters, shared by every session of a model, are not counted.
std::size_t estimate_plan_bytes(const NetworkWeights& weights, int model_height, int model_width);

// The limit in bytes: max_memory_mb, or with 0 three quarters of MemAvailable (/proc/meminfo);
// nullopt where there is none to apply (0 and no /proc/meminfo).
std::optional<std::size_t> memory_limit_bytes(int max_memory_mb);

// Why a plan at that model size does not fit the options' limit, or nullopt when it does.
std::optional<std::string> memory_problem(const NetworkWeights& weights, const SessionOptions& options,
                                          int model_height, int model_width);

}  // namespace neuflow::model
