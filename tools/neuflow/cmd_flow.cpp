// neuflow flow: optical flow between two images with a NeuFlow-V2 checkpoint.
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "common/image_header.hpp"
#include "common/model_path.hpp"
#include "common/session_options.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/visualize.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace neuflow::cli {

namespace {

struct FlowArgs {
  std::string model, image0, image1, output, viz;
  SessionArgs session;
  double max_flow = 0;
};

void require_image_file(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw CommandError(kExitNoInput, path + ": no such image file");
}

// Refused by the size its header states where the session could not take frames that large,
// before decoding (which would take the memory first).
cv::Mat read_image(const std::string& path, const model::FlowSession& session) {
  const auto check = [&](int w, int h) { return session.frame_problem(w, h); };
  if (auto problem = image_too_large(path, check)) throw CommandError(kExitDataError, *problem);
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
    throw CommandError(kExitUsage, a.output + ": the output's extension must be .flo, .npy or .png");
  }
  const model::SessionOptions options = session_options(a.session);
  const std::string model_path = resolve_model(a.model, "flow");  // a usage error before any file is read
  require_image_file(a.image0);
  require_image_file(a.image1);
  const auto model = load_model(model_path);
  model::FlowSession session(model, options);
  std::string announced = announce_backend(session, "flow");
  const cv::Mat img0 = read_image(a.image0, session), img1 = read_image(a.image1, session);
  if (img0.size() != img1.size()) {
    throw CommandError(kExitDataError, a.image0 + " and " + a.image1 + " differ in size");
  }
  const auto view = [](const cv::Mat& m) {  // OpenCV decodes to BGR
    return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), model::ChannelOrder::bgr};
  };
  const auto t0 = std::chrono::steady_clock::now();
  flow::FlowField field;
  try {
    field = session.compute(view(img0), view(img1));
  } catch (const std::invalid_argument& e) {
    throw CommandError(kExitDataError, e.what());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report_late_fallback(session, "flow", announced);

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
  sub->add_option("--model,-m", args->model, kModelOptionHelp);
  add_session_options(*sub, args->session);
  sub->add_option("--viz", args->viz, "Also write the colour-wheel rendering of the flow to this PNG");
  sub->add_option("--max-flow", args->max_flow,
                  "Magnitude (px) of full saturation in --viz; default: the image's largest");
  sub->add_option("IMG0", args->image0, "First frame")->required();
  sub->add_option("IMG1", args->image1, "Second frame")->required();
  sub->add_option("OUT", args->output, "Output flow file: .flo, .npy or .png (KITTI 16-bit)")->required();
  sub->callback([args] { run_flow(*args); });
}

}  // namespace neuflow::cli
