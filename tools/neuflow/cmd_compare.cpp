// `neuflow compare PRED GT [--json] [--error-map FILE.png]`: accuracy of a predicted flow file
// against ground truth, and where the error is.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "common/png_name.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/figures.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/metrics.hpp"

namespace neuflow::cli {

namespace {

struct CompareOptions {
  std::string predicted;
  std::string ground_truth;
  bool json = false;
  bool use_predicted_mask = false;
  std::string error_map;  // --error-map: empty for none
};

flow::FlowField read(const std::string& path) {
  try {
    return flow::read_flow(path);
  } catch (const flow::FlowFileError& e) {
    throw CommandError(exit_code_for(e), std::string("compare: ") + e.what());
  }
}

// JSON has no NaN or infinity; null says "not available" (no valid pixel, or a non-finite
// prediction).
std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

void print_text(const flow::FlowMetrics& m) {
  auto line = [](const char* name, double value, double scale, const char* unit, int precision) {
    if (std::isnan(value)) {
      std::printf("%-7s %10s\n", name, "n/a");
    } else {
      std::printf("%-7s %10.*f %s\n", name, precision, value * scale, unit);
    }
  };
  line("EPE", m.epe, 1.0, "px", 4);
  line("Fl-all", m.fl_all, 100.0, "%", 2);
  line("<1px", m.within_1px, 100.0, "%", 2);
  line("<3px", m.within_3px, 100.0, "%", 2);
  line("<5px", m.within_5px, 100.0, "%", 2);
  std::printf("%-7s %10zu of %zu px\n", "valid", m.valid_pixels, m.total_pixels);
}

void print_json(const flow::FlowMetrics& m) {
  std::printf(
      "{\"epe\": %s, \"fl_all\": %s, \"within_1px\": %s, \"within_3px\": %s, "
      "\"within_5px\": %s, \"valid_pixels\": %zu, \"total_pixels\": %zu}\n",
      json_number(m.epe).c_str(), json_number(m.fl_all).c_str(), json_number(m.within_1px).c_str(),
      json_number(m.within_3px).c_str(), json_number(m.within_5px).c_str(), m.valid_pixels, m.total_pixels);
}

void run_compare(const CompareOptions& options) {
  const flow::FlowField predicted = read(options.predicted);
  const flow::FlowField ground_truth = read(options.ground_truth);
  if (predicted.width != ground_truth.width || predicted.height != ground_truth.height) {
    throw CommandError(kExitDataError, "compare: " + options.predicted + " is " + std::to_string(predicted.width) +
                                           "x" + std::to_string(predicted.height) + " but " + options.ground_truth +
                                           " is " + std::to_string(ground_truth.width) + "x" +
                                           std::to_string(ground_truth.height));
  }
  flow::MetricsOptions metrics_options;
  metrics_options.use_predicted_mask = options.use_predicted_mask;
  const flow::FlowMetrics m = flow::compute_metrics(predicted, ground_truth, metrics_options);
  if (!options.error_map.empty()) {
    // The pixels the EPE in its corner counts: with --pred-mask, also valid in the prediction.
    flow::FlowField scored = ground_truth;
    if (options.use_predicted_mask && predicted.has_mask()) {
      if (!scored.has_mask()) scored.valid.assign(scored.pixel_count(), 1);
      for (std::size_t i = 0; i < scored.valid.size(); ++i) scored.valid[i] &= predicted.valid[i];
    }
    flow::RgbImage map = flow::error_map(predicted, scored);
    char label[64];
    std::snprintf(label, sizeof label, std::isfinite(m.epe) ? "EPE %.3f px" : "EPE n/a", m.epe);
    flow::draw_label(map, label);
    try {
      flow::write_rgb_png(map, options.error_map);
    } catch (const flow::FlowFileError& e) {
      throw CommandError(exit_code_for(e), std::string("compare: ") + e.what());
    }
  }
  if (options.json) {
    print_json(m);
  } else {
    print_text(m);
    if (!options.error_map.empty()) std::printf("wrote %s\n", options.error_map.c_str());
  }
}

}  // namespace

void register_compare(CLI::App& app) {
  auto options = std::make_shared<CompareOptions>();
  CLI::App* cmd =
      app.add_subcommand("compare", "Score a predicted flow file against ground truth (EPE, Fl-all, 1/3/5 px)");
  cmd->footer(
      "Pixels count where the ground truth is valid. Fl-all (KITTI): share of pixels whose "
      "error is > 3 px and > 5% of the true magnitude.\nExit status: 65 malformed input or "
      "size mismatch, 66 missing input.");
  cmd->add_option("PRED", options->predicted, "Predicted flow (.flo, .png, .npy)")->required();
  cmd->add_option("GT", options->ground_truth, "Ground-truth flow (.flo, .png, .npy)")->required();
  cmd->add_flag("--json", options->json, "Print one JSON object (ratios as fractions, not %)");
  cmd->add_flag("--pred-mask", options->use_predicted_mask,
                "Also skip pixels that are invalid in the prediction (default: score them as "
                "they are)");
  cmd->add_option("--error-map", options->error_map,
                  "Also write the end-point error of every scored pixel as a PNG: a colour map (dark: none, "
                  "yellow: the largest) with its scale bar, the EPE in the corner, unscored pixels grey")
      ->check(png_name);
  cmd->callback([options] { run_compare(*options); });
}

}  // namespace neuflow::cli
