// The core against the reference implementation's tensors for every stage
// (shared/fixtures/neuflow-v2-seed0: random weights, 320×256, iters 1 + 8).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <string>

#include "neuflow/flow/npy_format.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "support/fixtures.hpp"
#include "support/vulkan.hpp"

namespace neuflow::model {
namespace {

struct Captured {
  int h, w, c;
  std::vector<float> data;  // NHWC
};

// "frameN" suffix for per-frame tensors (the fixture stacks both frames along N).
std::string key(const std::string& name, int frame) { return name + "#" + std::to_string(frame); }

// absmax of each fixture tensor, from manifest.json (avoids a JSON dependency for one field).
std::map<std::string, double> read_absmax(const std::filesystem::path& manifest) {
  std::ifstream in(manifest);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::map<std::string, double> out;
  const std::regex entry(R"re("([a-z0-9_]+)": \{\s*"shape": \[[^\]]*\],\s*"absmax": ([0-9.eE+-]+))re");
  for (std::sregex_iterator it(text.begin(), text.end(), entry), end; it != end; ++it) {
    out[(*it)[1]] = std::stod((*it)[2]);
  }
  return out;
}

ImageView view_of(const cv::Mat& bgr) {
  return ImageView{bgr.data, bgr.cols, bgr.rows, static_cast<std::ptrdiff_t>(bgr.step[0]), ChannelOrder::bgr};
}

// Both backends against the same reference at the same tolerances.
class NetworkReference : public ::testing::TestWithParam<Backend> {};

TEST_P(NetworkReference, EveryStageMatchesTheReference) {
  NEUFLOW_REQUIRE_FIXTURE(dir, "neuflow-v2-seed0");
  if (GetParam() == Backend::vulkan) {
    NEUFLOW_REQUIRE_VULKAN();
  }
  const auto absmax = read_absmax(dir / "manifest.json");
  ASSERT_EQ(absmax.size(), 28u) << "manifest.json not understood";

  const auto model = FlowModel::load(dir / "checkpoint.pth");
  FlowSession session(model, {.iterations = {1, 8}, .threads = 2, .backend = GetParam()});
  std::map<std::string, Captured> seen;
  session.set_observer([&](const StageTensor& t) {
    seen[key(t.name, t.frame)] = {
        t.height, t.width, t.channels,
        std::vector<float>(t.data, t.data + static_cast<std::size_t>(t.height) * t.width * t.channels)};
  });
  const cv::Mat img0 = cv::imread((dir / "frame0.png").string(), cv::IMREAD_COLOR);
  const cv::Mat img1 = cv::imread((dir / "frame1.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img0.empty());
  const flow::FlowField result = session.compute(view_of(img0), view_of(img1));

  int compared = 0;
  for (const auto& [name, magnitude] : absmax) {
    const auto ref = neuflow::flow::read_npy_array(dir / (name + ".npy"));
    ASSERT_EQ(ref.shape.size(), 4u) << name;
    const int n = static_cast<int>(ref.shape[0]), c = static_cast<int>(ref.shape[1]);
    const int h = static_cast<int>(ref.shape[2]), w = static_cast<int>(ref.shape[3]);
    for (int frame = 0; frame < n; ++frame) {
      const auto it = seen.find(key(name, frame));
      ASSERT_NE(it, seen.end()) << "the core never produced " << name << " for frame " << frame;
      const Captured& got = it->second;
      ASSERT_EQ(got.h, h) << name;
      ASSERT_EQ(got.w, w) << name;
      ASSERT_EQ(got.c, c) << name;
      double max_err = 0, sum_err = 0;
      int worst = 0;
      for (int ch = 0; ch < c; ++ch) {
        for (int p = 0; p < h * w; ++p) {
          const float r = ref.data[(static_cast<std::size_t>(frame) * c + ch) * h * w + p];
          const float g = got.data[static_cast<std::size_t>(p) * c + ch];
          const double e = std::fabs(static_cast<double>(r) - g);
          sum_err += e;
          if (e > max_err) {
            max_err = e;
            worst = ch * h * w + p;
          }
        }
      }
      const double mean_err = sum_err / (static_cast<double>(c) * h * w);
      if (name == "flow") {
        EXPECT_LT(max_err, 1e-2) << "final flow, worst at channel " << worst / (h * w) << " pixel " << worst % (h * w);
        EXPECT_LT(mean_err, 1e-3) << "final flow";
      } else {
        EXPECT_LT(max_err, 1e-3 * magnitude)
            << name << " frame " << frame << ": max error " << max_err << " (absmax " << magnitude << "), mean "
            << mean_err << ", worst at channel " << worst / (h * w) << " pixel " << worst % (h * w);
      }
      RecordProperty(name + "_frame" + std::to_string(frame) + "_max_err", std::to_string(max_err));
      ++compared;
    }
  }
  EXPECT_EQ(compared, 32);

  // The returned field is the final flow, interleaved, at the frame's size.
  const auto ref = neuflow::flow::read_npy_array(dir / "flow.npy");
  ASSERT_EQ(result.width, 320);
  ASSERT_EQ(result.height, 256);
  double max_err = 0;
  for (int p = 0; p < 320 * 256; ++p) {
    max_err = std::max(max_err, static_cast<double>(std::fabs(result.uv[2 * p] - ref.data[p])));
    max_err = std::max(max_err, static_cast<double>(std::fabs(result.uv[2 * p + 1] - ref.data[320 * 256 + p])));
  }
  EXPECT_LT(max_err, 1e-2);
  if (GetParam() == Backend::vulkan) {
    NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, NetworkReference, ::testing::Values(Backend::cpu, Backend::vulkan),
                         [](const ::testing::TestParamInfo<Backend>& param) {
                           return std::string(backend_name(param.param));
                         });

}  // namespace
}  // namespace neuflow::model
