// The products on tensor cores (matmul_fragments.comp): fp16 operands and fp32 sums in 16×16
// fragments. Lavapipe has no cooperative matrices, so here the emulated twin runs (the same
// tiles, operands, staging and epilogue; NEUFLOW_VULKAN_PRODUCTS=twin): every product of the
// network goes through it and the flow stays within the fp16 bound of fp32. On a GPU with
// VK_NV_cooperative_matrix (scripts/gpu-check.sh), the real fragments are held to their twin.
// Runs under the validation layer.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "support/camera_frames.hpp"
#include "support/fixtures.hpp"
#include "support/flow_difference.hpp"
#include "support/flow_error.hpp"
#include "support/vulkan.hpp"

namespace neuflow::model {
namespace {

// Sets NEUFLOW_VULKAN_PRODUCTS (and NEUFLOW_VULKAN_CONV, NEUFLOW_VULKAN_GEMM_TILE) for the
// sessions made in its scope.
class ProductKernelsScope {
 public:
  explicit ProductKernelsScope(const char* products, const char* conv = "winograd", const char* tile = "auto") {
    setenv("NEUFLOW_VULKAN_PRODUCTS", products, 1);
    setenv("NEUFLOW_VULKAN_CONV", conv, 1);
    setenv("NEUFLOW_VULKAN_GEMM_TILE", tile, 1);
  }
  ~ProductKernelsScope() {
    unsetenv("NEUFLOW_VULKAN_PRODUCTS");
    unsetenv("NEUFLOW_VULKAN_CONV");
    unsetenv("NEUFLOW_VULKAN_GEMM_TILE");
  }
  ProductKernelsScope(const ProductKernelsScope&) = delete;
  ProductKernelsScope& operator=(const ProductKernelsScope&) = delete;
};

class VulkanTensorCores : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
    NEUFLOW_REQUIRE_FIXTURE(frames, "frames");
    NEUFLOW_REQUIRE_VULKAN();
    if (!list_gpu_devices().at(0).fp16) GTEST_SKIP() << "Vulkan device 0 has no fp16: the fragments multiply fp16";
    if (!model_) model_ = FlowModel::load(checkpoint);
    frames_folder_ = frames;
  }
  void TearDown() override { NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES(); }

  std::vector<cv::Mat> frames(int w, int h) const { return test::camera_frames(frames_folder_, 2, cv::Size(w, h)); }
  static SessionOptions options(Precision precision) {
    return {.iterations = {1, 4}, .backend = Backend::vulkan, .device = 0, .precision = precision};
  }

  static std::shared_ptr<const FlowModel> model_;
  std::filesystem::path frames_folder_;
};

std::shared_ptr<const FlowModel> VulkanTensorCores::model_;

const std::set<std::string> kScalarProducts{"conv2d",
                                            "matmul",
                                            "matmul_norm",
                                            "matmul_mlp_norm",
                                            "winograd_gemm",
                                            "winograd_conv",
                                            "winograd_conv_parts",
                                            "winograd_conv_step",
                                            "winograd_conv_step_end",
                                            "conv2d_convex"};

// The kernels of a streamed frame's commands, each once.
std::set<std::string> kernels_of(const DeviceWork& work) {
  std::set<std::string> names;
  for (const auto& c : work.commands) names.insert(c.kernel);
  return names;
}

// With the twin every product of a streamed frame runs on it: the implicit-GEMM convolutions
// (all of them with NEUFLOW_VULKAN_CONV=direct), the Winograd convolutions (fused, or their
// products split from the transforms) and the matrix products, with the multiply-adds of the
// scalar kernels they stand for, in the same commands. The grids are the same too, but for the
// fused Winograd convolution's (16 tiles a workgroup where the scalar one takes 32). So the
// parity below covers every layer shape the network has.
TEST_F(VulkanTensorCores, TheTwinRunsEveryProductOfTheNetwork) {
  // At 160×128 the 1/8 layers take Winograd and the 1/16 ones not; with every convolution
  // direct, the smallest size does.
  for (const auto& [conv, w, h] : std::vector<std::tuple<const char*, int, int>>{
           {"winograd", 160, 128}, {"winograd-split", 160, 128}, {"direct", 96, 64}}) {
    const auto f = frames(w, h);
    DeviceWork scalar, twin;
    {
      const ProductKernelsScope scope("scalar", conv);
      FlowSession s(model_, options(Precision::fp16));
      s.push(test::bgr_view(f[0]));
      ASSERT_TRUE(s.push(test::bgr_view(f[1])).has_value());
      scalar = s.device_work();
    }
    {
      const ProductKernelsScope scope("twin", conv);
      FlowSession s(model_, options(Precision::fp16));
      EXPECT_NE(s.backend_description().find(", fp16, tensor cores emulated"), std::string::npos)
          << s.backend_description();
      s.push(test::bgr_view(f[0]));
      ASSERT_TRUE(s.push(test::bgr_view(f[1])).has_value());
      twin = s.device_work();
    }
    ASSERT_EQ(scalar.commands.size(), twin.commands.size()) << conv;
    int products = 0;
    for (std::size_t i = 0; i < scalar.commands.size(); ++i) {
      const DeviceCommand &a = scalar.commands[i], &b = twin.commands[i];
      if (kScalarProducts.contains(a.kernel)) {
        EXPECT_EQ(b.kernel, a.kernel + "_coopmat_twin") << a.stage;
        ++products;
      } else {
        EXPECT_EQ(b.kernel, a.kernel) << a.stage;
      }
      if (a.kernel.starts_with("winograd_conv_step")) {
        // 16 tiles a workgroup for the hidden state's 4 channel groups; the correlation's alike
        EXPECT_EQ(b.workgroups, a.workgroups + 4) << a.stage;
      } else if (a.kernel.starts_with("winograd_conv")) {
        EXPECT_EQ(b.workgroups, 2 * a.workgroups) << a.stage;  // 16 tiles a workgroup, not 32: 20 tiles here
      } else {
        EXPECT_EQ(a.workgroups, b.workgroups) << a.kernel << " in " << a.stage;
      }
      EXPECT_EQ(a.multiply_adds, b.multiply_adds) << a.kernel << " in " << a.stage;
    }
    std::printf("%s: %d products on the twin\n", conv, products);
    const auto names = kernels_of(twin);
    EXPECT_TRUE(names.contains("conv2d_coopmat_twin")) << conv;
    EXPECT_TRUE(names.contains("matmul_coopmat_twin")) << conv;
    EXPECT_TRUE(names.contains("matmul_norm_coopmat_twin")) << conv;
    EXPECT_TRUE(names.contains("matmul_mlp_norm_coopmat_twin")) << conv;
    EXPECT_TRUE(names.contains("conv2d_convex_coopmat_twin")) << conv;
    EXPECT_EQ(names.contains("winograd_gemm_coopmat_twin"), std::string(conv) == "winograd-split") << conv;
    EXPECT_EQ(names.contains("winograd_conv_coopmat_twin"), std::string(conv) == "winograd") << conv;
    EXPECT_EQ(names.contains("winograd_conv_step_coopmat_twin"), std::string(conv) == "winograd") << conv;
    EXPECT_EQ(names.contains("winograd_conv_step_end_coopmat_twin"), std::string(conv) == "winograd") << conv;
  }
}

// The twin's flow against fp32's: within the bound fp16 storage is held to, with the Winograd
// products (160×128, the smallest size whose 1/8 layers take them) and with every convolution
// direct (at a size that is not a multiple of 16).
TEST_F(VulkanTensorCores, TheTwinStaysWithinTheFp16BoundOfFp32) {
  FlowSession fp32(model_, options(Precision::fp32));
  for (const auto& [w, h, conv] :
       std::vector<std::tuple<int, int, const char*>>{{160, 128, "winograd"}, {100, 60, "direct"}}) {
    const auto f = frames(w, h);
    const ProductKernelsScope scope("twin", conv);
    FlowSession twin(model_, options(Precision::fp16));
    const std::string where = std::to_string(w) + "x" + std::to_string(h) + ", " + conv;
    const test::Fp16Error e = test::fp16_error(fp32.compute(test::bgr_view(f[0]), test::bgr_view(f[1])),
                                               twin.compute(test::bgr_view(f[0]), test::bgr_view(f[1])), w, h,
                                               ("tensor-core twin vs fp32, " + std::string(conv)).c_str());
    RecordProperty("twin_mean_epe_" + std::to_string(w) + "x" + std::to_string(h) + "_" + conv, std::to_string(e.epe));
    test::expect_within_fp16_bound(e, where.c_str());
  }
}

// The twin in each of its tiles (NEUFLOW_VULKAN_GEMM_TILE): 32×32 (4 subgroups of one fragment),
// 64×64 (4 of 2×2) and 128×128 (8 of 2×4), with every convolution direct and with the split
// Winograd's 36 batched products. Each output's fragment products are summed in K order at
// every size, so the flows agree to the bit; auto, which the other tests run, takes them by
// the grid, and holds the twin within the fp16 bound above.
TEST_F(VulkanTensorCores, TheTwinsTilesAgreeToTheBit) {
  const auto flow_with = [&](int w, int h, const char* conv, const char* tile) {
    const auto f = frames(w, h);
    const ProductKernelsScope scope("twin", conv, tile);
    FlowSession twin(model_, options(Precision::fp16));
    return twin.compute(test::bgr_view(f[0]), test::bgr_view(f[1]));
  };
  EXPECT_EQ(test::differing_values(flow_with(100, 60, "direct", "32"), flow_with(100, 60, "direct", "128")), 0U);
  EXPECT_EQ(
      test::differing_values(flow_with(160, 128, "winograd-split", "128"), flow_with(160, 128, "winograd-split", "64")),
      0U);
}

// What NEUFLOW_VULKAN_PRODUCTS cannot do is an error saying why: tensor cores on a device
// without them, fp16 operands in an fp32 session, a value it does not know.
TEST_F(VulkanTensorCores, AnImpossibleChoiceIsAnErrorSayingWhy) {
  const auto expect_error = [&](const char* value, Precision precision, const char* says) {
    const ProductKernelsScope scope(value);
    try {
      FlowSession s(model_, options(precision));
      ADD_FAILURE() << "NEUFLOW_VULKAN_PRODUCTS=" << value << " was accepted: " << s.backend_description();
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  if (!list_gpu_devices().at(0).tensor_cores) {
    expect_error("tensor-cores", Precision::fp16, "no VK_NV_cooperative_matrix");
  }
  expect_error("twin", Precision::fp32, "needs precision fp16");
  expect_error("fast", Precision::fp16, "expected auto, scalar, tensor-cores or twin");
}

// On a GPU with tensor cores (none in CI: lavapipe has no cooperative matrices, so this skips
// there): fp16 sessions take them by default, and their flow is the twin's up to the order the
// fragments sum in, at the sizes the benchmarks run.
TEST_F(VulkanTensorCores, RealFragmentsAgreeWithTheirTwin) {
  if (!list_gpu_devices().at(0).tensor_cores) {
    GTEST_SKIP() << "Vulkan device 0 has no VK_NV_cooperative_matrix with 16x16x16 fp16 products (lavapipe has "
                    "none): scripts/gpu-check.sh runs this on a GPU";
  }
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{200, 120}, {768, 432}}) {
    const auto f = frames(w, h);
    FlowSession cores(model_, options(Precision::fp16));
    EXPECT_NE(cores.backend_description().find(", fp16, tensor cores"), std::string::npos)
        << cores.backend_description();
    const auto real = cores.compute(test::bgr_view(f[0]), test::bgr_view(f[1]));
    const ProductKernelsScope scope("twin");
    FlowSession twin(model_, options(Precision::fp16));
    const test::Fp16Error e =
        test::fp16_error(twin.compute(test::bgr_view(f[0]), test::bgr_view(f[1])), real, w, h, "tensor cores vs twin");
    test::expect_within_fp16_bound(e, (std::to_string(w) + "x" + std::to_string(h)).c_str());
  }
}

}  // namespace
}  // namespace neuflow::model
