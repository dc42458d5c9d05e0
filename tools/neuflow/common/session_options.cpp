#include "common/session_options.hpp"

#include <cctype>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "common/exit_codes.hpp"
#include "neuflow/model/session_option_docs.hpp"

namespace neuflow::cli {

namespace {
namespace docs = model::option_docs;
// The option as the element's property and neuflowd's key name it, with the same help.
std::string flag(const model::OptionDoc& doc) { return "--" + std::string(doc.name); }
std::string help(const model::OptionDoc& doc) { return std::string(doc.help); }

// The session's messages name settings ("model-width and model-height go together"); on the
// command line each is an option: "--model-width and --model-height go together".
std::string as_flags(std::string message) {
  for (const model::OptionDoc* doc : {&docs::iters_s16, &docs::iters_s8, &docs::model_width, &docs::model_height,
                                      &docs::threads, &docs::device, &docs::max_memory}) {
    const std::string name(doc->name);
    for (std::size_t at = message.find(name); at != std::string::npos; at = message.find(name, at + name.size() + 2)) {
      const bool word_start =
          at == 0 || (message[at - 1] != '-' && !std::isalnum(static_cast<unsigned char>(message[at - 1])));
      const std::size_t end = at + name.size();
      const bool word_end = end == message.size() || !std::isalnum(static_cast<unsigned char>(message[end]));
      if (word_start && word_end) message.insert(at, "--");
    }
  }
  return message;
}
}  // namespace

void add_session_options(CLI::App& command, SessionArgs& args, ModelSizeOptions model_size) {
  using L = model::SessionLimits;
  auto& o = args.options;
  if (model_size == ModelSizeOptions::offered) {
    command.add_option(flag(docs::model_width), o.model_width, help(docs::model_width))
        ->capture_default_str()
        ->check(CLI::Range(0, L::max_side));
    command.add_option(flag(docs::model_height), o.model_height, help(docs::model_height))
        ->capture_default_str()
        ->check(CLI::Range(0, L::max_side));
    // Hidden (an empty group): the spelling of earlier releases.
    command.add_option("--size", args.size_alias, "Same as --model-width W --model-height H")->group("");
  }
  command.add_option(flag(docs::iters_s16), o.iterations.s16, help(docs::iters_s16))
      ->capture_default_str()
      ->check(CLI::Range(0, L::max_iterations_s16));
  command.add_option(flag(docs::iters_s8), o.iterations.s8, help(docs::iters_s8))
      ->capture_default_str()
      ->check(CLI::Range(0, L::max_iterations_s8));
  command.add_option(flag(docs::channel_order), args.channel_order, help(docs::channel_order))
      ->check(CLI::IsMember({"rgb", "bgr"}))
      ->capture_default_str();
  command.add_flag("--bgr", args.bgr_alias, "Same as --channel-order bgr")->group("");
  command.add_option(flag(docs::threads), o.threads, help(docs::threads))
      ->capture_default_str()
      ->check(CLI::Range(0, L::max_threads));
  command.add_option(flag(docs::backend), args.backend, help(docs::backend))
      ->check(CLI::IsMember({"auto", "cpu", "vulkan"}))
      ->capture_default_str();
  command.add_option(flag(docs::device), o.device, help(docs::device))
      ->capture_default_str()
      ->check(CLI::Range(-1, L::max_device));
  command.add_option(flag(docs::precision), args.precision, help(docs::precision))
      ->check(CLI::IsMember({"fp32", "fp16"}))
      ->capture_default_str();
  command.add_option(flag(docs::max_memory), o.max_memory_mb, help(docs::max_memory))
      ->capture_default_str()
      ->check(CLI::Range(0, L::max_memory_mb));
}

void report_late_fallback(const model::FlowSession& session, const char* subcommand, std::string& announced) {
  if (session.fallback_warning().empty() || session.fallback_warning() == announced) return;
  announced = session.fallback_warning();
  std::fprintf(stderr, "neuflow %s: warning: %s (ran on %s)\n", subcommand, session.fallback_warning().c_str(),
               session.backend_description().c_str());
}

std::string announce_backend(const model::FlowSession& session, const char* subcommand) {
  if (!session.fallback_warning().empty()) {
    std::fprintf(stderr, "neuflow %s: warning: %s\n", subcommand, session.fallback_warning().c_str());
  }
  std::fprintf(stderr, "neuflow %s: running on %s\n", subcommand, session.backend_description().c_str());
  return session.fallback_warning();
}

model::SessionOptions session_options(const SessionArgs& args) {
  model::SessionOptions options = args.options;
  if (!args.size_alias.empty()) {
    char rest = 0;
    if (std::sscanf(args.size_alias.c_str(), "%dx%d%c", &options.model_width, &options.model_height, &rest) != 2) {
      throw CommandError(kExitUsage, "--size wants WIDTHxHEIGHT (multiples of 16), got '" + args.size_alias + "'");
    }
  }
  options.network_order = args.bgr_alias
                              ? model::ChannelOrder::bgr
                              : model::parse_channel_order(args.channel_order).value_or(model::ChannelOrder::rgb);
  options.backend = model::parse_backend(args.backend).value_or(model::Backend::automatic);
  options.precision = model::parse_precision(args.precision).value_or(model::Precision::fp32);
  if (auto problem = model::check_session_options(options)) throw CommandError(kExitUsage, as_flags(*problem));
  try {
    model::cpu_convolution_from_environment();
  } catch (const std::invalid_argument& e) {
    throw CommandError(kExitConfig, e.what());
  }
  return options;
}

}  // namespace neuflow::cli
