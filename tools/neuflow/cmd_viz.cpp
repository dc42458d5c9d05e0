// `neuflow viz FLOW [-o OUT.png] [--max-flow N] [--key] [--arrows] [--overlay IMAGE]`: renders
// a flow file with the standard Middlebury colour wheel, as the neuflowviz element draws it.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "common/png_name.hpp"
#include "neuflow/flow/arrows.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/figures.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/visualize.hpp"

namespace neuflow::cli {

namespace {

struct VizOptions {
  std::string input;
  std::string output;
  double max_flow = 0;
  bool fixed_max = false;
  bool key = false;
  bool arrows = false;
  int arrow_spacing = flow::kArrowSpacing;
  std::string overlay;  // the frame to draw over; empty: the rendering alone
  double alpha = flow::kOverlayAlpha;
};

// The frame the flow is drawn over, as RGB, at the flow's size.
flow::RgbImage read_overlay(const std::string& path, int width, int height) {
  const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw CommandError(kExitNoInput, "viz: --overlay " + path + ": cannot read it as an image (PNG, JPEG, ...)");
  }
  if (bgr.cols != width || bgr.rows != height) {
    throw CommandError(kExitDataError, "viz: --overlay " + path + " is " + std::to_string(bgr.cols) + "x" +
                                           std::to_string(bgr.rows) + " but the flow is " + std::to_string(width) +
                                           "x" + std::to_string(height) + ": give the flow's first frame");
  }
  flow::RgbImage image{width, height, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(width) * height)};
  cv::Mat rgb(height, width, CV_8UC3, image.rgb.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return image;
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
  flow::RgbImage picture = result.image;
  if (!options.overlay.empty()) {
    picture = flow::blend(read_overlay(options.overlay, field.width, field.height), picture, options.alpha);
  }
  if (options.arrows) {
    const flow::ArrowScale scale = flow::automatic_arrow_scale(options.arrow_spacing, result.max_flow);
    flow::draw_arrows(picture, field, options.arrow_spacing, scale.scale, scale.max_length);
  }
  if (options.key) flow::draw_key(picture, result.max_flow);

  try {
    flow::write_rgb_png(picture, options.output);
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
      ->check(png_name);
  CLI::Option* max_flow = cmd->add_option("--max-flow", options->max_flow,
                                          "Magnitude in px drawn fully saturated; larger vectors are dimmed. "
                                          "Default: the largest valid magnitude of the field")
                              ->check(CLI::PositiveNumber);
  cmd->add_flag("--key", options->key,
                "Draw the colour wheel in the bottom-right corner, its rim at the max flow, labelled with it");
  CLI::Option* arrows =
      cmd->add_flag("--arrows", options->arrows,
                    "Draw an arrow every --arrow-spacing pixels; a vector of the max flow is one spacing long");
  cmd->add_option("--arrow-spacing", options->arrow_spacing, "Pixels between arrows (with --arrows)")
      ->capture_default_str()
      ->check(CLI::Range(4, 1024))
      ->needs(arrows);
  CLI::Option* overlay = cmd->add_option(
      "--overlay", options->overlay,
      "Blend the rendering over this image (the flow's first frame, same size) instead of drawing it alone");
  cmd->add_option("--alpha", options->alpha, "Opacity of the colours with --overlay (0: image only, 1: flow only)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->needs(overlay);
  cmd->callback([options, max_flow] {
    options->fixed_max = max_flow->count() > 0;
    run_viz(*options);
  });
}

}  // namespace neuflow::cli
