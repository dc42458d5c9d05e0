// neuflow flow: optical flow between two images with a NeuFlow-V2 checkpoint.
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/visualize.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace neuflow::cli {

namespace {

struct FlowArgs {
  std::string model, image0, image1, output, viz, size;
  int iters_s16 = 1;
  int iters_s8 = 8;
  int threads = 0;
  bool bgr = false;
  double max_flow = 0;
};

cv::Mat read_image(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw CommandError(kExitNoInput, path + ": no such image file");
  cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  if (img.empty()) throw CommandError(kExitDataError, path + ": not an image OpenCV can decode");
  return img;
}

std::shared_ptr<const model::FlowModel> load_model(const std::string& path) {
  try {
    return model::FlowModel::load(path);
  } catch (const model::CheckpointError& e) {
    throw CommandError(exit_code_for(e), e.what());
  }
}

void run_flow(const FlowArgs& a) {
  if (!flow::flow_format_from_path(a.output)) {
    throw CommandError(kExitFailure, a.output + ": the output's extension must be .flo, .npy or .png");
  }
  model::SessionOptions options;
  options.iterations = {a.iters_s16, a.iters_s8};
  options.threads = a.threads;
  if (!a.size.empty() && std::sscanf(a.size.c_str(), "%dx%d", &options.model_width, &options.model_height) != 2) {
    throw CommandError(kExitFailure, "--size wants WIDTHxHEIGHT (multiples of 16), got '" + a.size + "'");
  }
  const cv::Mat img0 = read_image(a.image0), img1 = read_image(a.image1);
  if (img0.size() != img1.size()) {
    throw CommandError(kExitDataError, a.image0 + " and " + a.image1 + " differ in size");
  }
  const auto model = load_model(a.model);
  model::FlowSession session(model, options);
  // OpenCV decodes to BGR; the network wants RGB unless --bgr asks to feed BGR as the
  // reference demo scripts do.
  const auto order = a.bgr ? model::ChannelOrder::rgb : model::ChannelOrder::bgr;
  const auto view = [&](const cv::Mat& m) {
    return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), order};
  };
  const auto t0 = std::chrono::steady_clock::now();
  flow::FlowField field;
  try {
    field = session.compute(view(img0), view(img1));
  } catch (const std::invalid_argument& e) {
    throw CommandError(kExitDataError, e.what());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  try {
    flow::write_flow(field, a.output);
    if (!a.viz.empty()) {
      flow::VisualizeOptions vo;
      if (a.max_flow > 0) vo.max_flow = a.max_flow;
      flow::write_rgb_png(flow::visualize_flow(field, vo).image, a.viz);
    }
  } catch (const flow::FlowFileError& e) {
    throw CommandError(exit_code_for(e), e.what());
  }
  std::fprintf(stderr, "%s: %dx%d flow in %.2f s, max |flow| %.2f px\n", a.output.c_str(), field.width, field.height,
               seconds, flow::max_flow_magnitude(field));
}

}  // namespace

void register_flow(CLI::App& app) {
  auto args = std::make_shared<FlowArgs>();
  auto* sub = app.add_subcommand("flow", "Compute the optical flow from IMG0 to IMG1 and write it to OUT");
  sub->add_option("--model,-m", args->model, "NeuFlow-V2 checkpoint (.pth), e.g. neuflow_mixed.pth")->required();
  sub->add_option("--iters-s16", args->iters_s16, "Refinement iterations at 1/16 resolution")->capture_default_str()->check(CLI::Range(0, 32));
  sub->add_option("--iters-s8", args->iters_s8, "Refinement iterations at 1/8 resolution")->capture_default_str()->check(CLI::Range(0, 64));
  sub->add_option("--size", args->size, "Run the network at WIDTHxHEIGHT (multiples of 16) and resize the flow back; default: the images' size, edge-padded");
  sub->add_option("--threads", args->threads, "CPU threads (0: all cores)")->capture_default_str()->check(CLI::NonNegativeNumber);
  sub->add_flag("--bgr", args->bgr, "Feed the network BGR instead of RGB (as the reference demo scripts do)");
  sub->add_option("--viz", args->viz, "Also write the colour-wheel rendering of the flow to this PNG");
  sub->add_option("--max-flow", args->max_flow, "Magnitude (px) of full saturation in --viz; default: the image's largest");
  sub->add_option("IMG0", args->image0, "First frame")->required();
  sub->add_option("IMG1", args->image1, "Second frame")->required();
  sub->add_option("OUT", args->output, "Output flow file: .flo, .npy or .png (KITTI 16-bit)")->required();
  sub->callback([args] { run_flow(*args); });
}

}  // namespace neuflow::cli
