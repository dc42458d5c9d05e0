#pragma once
// The model options every subcommand that runs the network takes, under the names the
// element and the daemon's config use (--model-width, --model-height, --iters-s16,
// --iters-s8, --threads, --channel-order), with defaults and limits from
// neuflow/model/session_settings.hpp. `flow`'s earlier --size WxH and --bgr are kept as
// hidden aliases for one release.
#include <CLI/CLI.hpp>

#include <string>

#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::cli {

struct SessionArgs {
  model::SessionOptions options;
  std::string channel_order{model::channel_order_name(model::SessionOptions{}.network_order)};
  std::string size_alias;  // --size WxH
  bool bgr_alias = false;  // --bgr
  std::string backend{model::backend_name(model::SessionOptions{}.backend)};
  std::string precision{model::precision_name(model::SessionOptions{}.precision)};
};

enum class ModelSizeOptions { offered, not_offered };

// Registers the options on `command`; `args` must outlive the parse.
void add_session_options(CLI::App& command, SessionArgs& args, ModelSizeOptions model_size = ModelSizeOptions::offered);

// The parsed options, checked as the session checks them. Throws CommandError (kExitUsage)
// naming the option and what it expected.
model::SessionOptions session_options(const SessionArgs& args);

// One line on stderr saying where the network runs ("neuflow flow: running on vulkan device 0
// (...)"), and backend=auto's reason for not using a GPU it found, if any.
// Returns the warning it printed (empty: none).
std::string announce_backend(const model::FlowSession& session, const char* subcommand);
// After the work: a warning that came later than announce_backend (backend=auto leaves the GPU
// only once it knows the frames' size and the plan does not fit).
// `announced` is what was said so far; updated.
void report_late_fallback(const model::FlowSession& session, const char* subcommand, std::string& announced);

}  // namespace neuflow::cli
