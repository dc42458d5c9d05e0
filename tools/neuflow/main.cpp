// neuflow: NeuFlow-V2 optical flow from the command line.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "commands.hpp"
#include "common/usage_errors.hpp"
#include "neuflow/model/gpu_devices.hpp"

int main(int argc, char** argv) {
  CLI::App app{"neuflow: NeuFlow-V2 optical flow on the CPU or a GPU (Vulkan)"};
  app.set_version_flag("--version", std::string("neuflow ") + NEUFLOW_VERSION);
  app.require_subcommand(1);

  neuflow::cli::register_viz(app);
  neuflow::cli::register_compare(app);
  neuflow::cli::register_inspect(app);
  neuflow::cli::register_flow(app);
  neuflow::cli::register_convert(app);
  neuflow::cli::register_eval(app);
  neuflow::cli::register_fetch_model(app);
  neuflow::cli::register_devices(app);

  if (argc <= 1) return neuflow::cli::report_no_arguments(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return neuflow::cli::report_parse_error(app, e, argc, argv);
  } catch (const neuflow::cli::CommandError& e) {
    std::fprintf(stderr, "neuflow: %s\n", e.what());
    return e.exit_code;
  } catch (const neuflow::model::BackendError& e) {
    std::fprintf(stderr, "neuflow: %s\n", e.what());
    return neuflow::cli::kExitUnavailable;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow: %s\n", e.what());
    return neuflow::cli::kExitFailure;
  }
  return neuflow::cli::kExitOk;
}
