// `neuflow viz FLOW [-o OUT.png] [--max-flow N]`: renders a flow file with the standard
// Middlebury colour wheel.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/visualize.hpp"

namespace neuflow::cli {

namespace {

struct VizOptions {
  std::string input;
  std::string output;
  double max_flow = 0;
  bool fixed_max = false;
};

std::string require_png_name(const std::string& name) {
  std::string ext = name.size() >= 4 ? name.substr(name.size() - 4) : std::string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png" ? std::string() : "the output is written as PNG; give it a .png name";
}

void run_viz(const VizOptions& given) {
  VizOptions options = given;
  if (options.output.empty()) options.output = options.input + ".png";
  flow::FlowField field;
  try {
    field = flow::read_flow(options.input);
  } catch (const flow::FlowFileError& e) {
    throw CommandError(exit_code_for(e), std::string("viz: ") + e.what());
  }

  flow::VisualizeOptions vis;
  if (options.fixed_max) vis.max_flow = options.max_flow;
  const flow::Visualization result = flow::visualize_flow(field, vis);

  try {
    flow::write_rgb_png(result.image, options.output);
  } catch (const flow::FlowFileError& e) {
    throw CommandError(exit_code_for(e), std::string("viz: ") + e.what());
  }
  const auto invalid = static_cast<std::size_t>(std::count(field.valid.begin(), field.valid.end(), 0));
  std::printf("%s: %dx%d, %zu invalid pixels (black)\n", options.input.c_str(), field.width, field.height, invalid);
  std::printf("max flow: %.3f px (%s)\n", result.max_flow,
              options.fixed_max ? "fixed by --max-flow" : "largest valid magnitude in this field");
  std::printf("wrote %s\n", options.output.c_str());
}

}  // namespace

void register_viz(CLI::App& app) {
  auto options = std::make_shared<VizOptions>();
  CLI::App* cmd = app.add_subcommand("viz", "Render a flow file (.flo, KITTI .png, .npy) as a colour-wheel PNG");
  cmd->add_option("FLOW", options->input, "Flow file: .flo, KITTI 16-bit .png or .npy (HxWx2)")->required();
  cmd->add_option("-o,--output", options->output, "Output image (.png); default: FLOW's name plus .png, beside it")
      ->check(require_png_name);
  CLI::Option* max_flow = cmd->add_option("--max-flow", options->max_flow,
                                          "Magnitude in px drawn fully saturated; larger vectors are dimmed. "
                                          "Default: the largest valid magnitude of the field")
                              ->check(CLI::PositiveNumber);
  cmd->callback([options, max_flow] {
    options->fixed_max = max_flow->count() > 0;
    run_viz(*options);
  });
}

}  // namespace neuflow::cli
