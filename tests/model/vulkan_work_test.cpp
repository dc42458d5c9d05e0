// What a streamed frame asks of the GPU (FlowSession::device_work()): counted from the
// commands' shapes when the passes are recorded, so it is the same on lavapipe as on a GPU and
// can be held to budgets here. Not timed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/network_cost.hpp"
#include "support/camera_frames.hpp"
#include "support/fixtures.hpp"
#include "support/vulkan.hpp"
#include "vulkan/gemm_tile.hpp"

namespace neuflow::model {
namespace {

// A streamed frame's counts as of 2026-12-07, the same at any size whose attention fits one
// score block (1024×448 and beyond): a change that raises them fails here, and a change that
// lowers them lowers these. The GPU-throughput work aims at 100 dispatches and 100 barriers.
struct Budget {
  int dispatches, barriers;
  double bytes;  // read and written at 96×64 in fp32, the size tested here
};
// Every convolution by the direct implicit GEMM (NEUFLOW_VULKAN_CONV=direct): 70.90 MB, most of
// it weights (the 1/8 refinement reads its own at every step). In every form the convex
// upsampling is the epilogue of the product that computes its mask.
constexpr Budget kDirect{124, 113, 70.91e6};
// At 160×128 with the 1/8 layers' stride-1 3×3 convolutions by Winograd, fused: one dispatch
// each, reading and writing what the direct convolution does (the filters as their 9 taps,
// transformed as they are loaded). The merges' and the upsampler's first convolutions read their
// inputs where the concatenations' parts lie: three resamples and a copy fewer (and a barrier
// for each of the two steps they took). Each 1/8 step ends beside its conv3 (winograd_conv_step,
// the last winograd_conv_step_end): a dispatch and a barrier fewer a step. Each attention
// layer's two LayerNorms are the epilogues of the products before them (matmul_norm): 96.19 MB.
constexpr Budget kWinograd{113, 103, 96.2e6};
// The same in three dispatches each (NEUFLOW_VULKAN_CONV=winograd-split, as the tensor-core
// products run), the tiles and products through memory in fp32.
constexpr Budget kWinogradSplit{280, 267, 327.0e6};
// The fused form on tensor cores (their twin here) at 160×128 in fp16: 111.64 MB, where the
// scalar fused form reads and writes 47.72 MB and the split one on tensor cores 214.64 MB. In
// fp16 each attention layer's MLP is one dispatch with its LayerNorm (matmul_mlp_norm): two
// dispatches and two barriers fewer than in fp32. The
// difference to the scalar form is the filters, read as transformed at upload (36 fp16 points
// for 9 taps, padded to 16 channels): the 1/8 refinement reads its own at every step.
constexpr Budget kWinogradFragments{111, 101, 111.7e6};
constexpr double kWinogradRatioBudget = 0.55;  // measured 0.353

class VulkanWork : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
    NEUFLOW_REQUIRE_FIXTURE(frames, "frames");
    NEUFLOW_REQUIRE_VULKAN();
    if (!model_) model_ = FlowModel::load(checkpoint);
    frames_folder_ = frames;
    frames_ = test::camera_frames(frames, 3, cv::Size(kWidth, kHeight));
  }
  void TearDown() override { NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES(); }

  ImageView frame(int i) const { return test::bgr_view(frames_.at(static_cast<std::size_t>(i))); }

  static constexpr int kWidth = 96, kHeight = 64;
  static std::shared_ptr<const FlowModel> model_;
  std::filesystem::path frames_folder_;
  std::vector<cv::Mat> frames_;
};

std::shared_ptr<const FlowModel> VulkanWork::model_;

std::uint64_t multiply_adds_of(const DeviceWork& work, const std::set<std::string>& kernels) {
  std::uint64_t n = 0;
  for (const auto& c : work.commands) {
    if (kernels.contains(c.kernel)) n += c.multiply_adds;
  }
  return n;
}

// The scalar kernel a product's tensor-core variant stands for (fp16 sessions on a GPU with
// tensor cores run conv2d_coopmat where fp32 runs conv2d).
// The multiply-adds of the 64 zero rows by which the upsampler's mask product (576 rows of 512
// inputs at 1/8) is padded to whole 64-row tiles of 7 subpixels' logits (DeviceWeights::convex_mask).
double mask_padding(int height, int width) {
  const long pixels8 = static_cast<long>(height / 8) * (width / 8);  // the sides are multiples of 8
  return 64.0 * 512 * static_cast<double>(pixels8);
}

std::string scalar_kernel(const std::string& kernel) {
  for (const std::string suffix : {"_coopmat_twin", "_coopmat"}) {
    if (kernel.ends_with(suffix)) return kernel.substr(0, kernel.size() - suffix.size());
  }
  return kernel;
}

void print(const char* what, const DeviceWork& work) {
  std::printf(
      "a streamed frame, %s: %d dispatches, %d copies, %d barriers, %d submissions, %d host waits, "
      "%.3f GMAC, %.2f MB read, %.2f MB written\n",
      what, work.dispatches, work.copies, work.barriers, work.submissions, work.host_waits,
      static_cast<double>(work.multiply_adds()) / 1e9, static_cast<double>(work.bytes_read()) / 1e6,
      static_cast<double>(work.bytes_written()) / 1e6);
}

void expect_within(const DeviceWork& work, const Budget& budget) {
  EXPECT_LT(work.barriers, work.dispatches + work.copies) << "barriers only between dependent commands";
  EXPECT_LE(work.dispatches, budget.dispatches);
  EXPECT_LE(work.barriers, budget.barriers);
  EXPECT_LE(static_cast<double>(work.bytes_read() + work.bytes_written()), budget.bytes);
}

TEST_F(VulkanWork, AStreamedFrameIsCountedCommandByCommand) {
  ASSERT_EQ(setenv("NEUFLOW_VULKAN_CONV", "direct", 1), 0);
  FlowSession gpu(model_, {.backend = Backend::vulkan, .device = 0});
  unsetenv("NEUFLOW_VULKAN_CONV");
  gpu.push(frame(0));
  ASSERT_TRUE(gpu.push(frame(1)).has_value());
  const DeviceWork& work = gpu.device_work();
  print("direct convolutions", work);

  ASSERT_EQ(work.commands.size(), static_cast<std::size_t>(work.dispatches + work.copies));
  // push() encodes the frame and runs the flow pass: two submissions, each waited for.
  EXPECT_EQ(work.submissions, 2);
  EXPECT_EQ(work.host_waits, 2);
  for (const auto& c : work.commands) {
    if (c.kernel == "copy") continue;
    EXPECT_GE(c.workgroups, 1u) << c.kernel << " in " << c.stage;
    EXPECT_GT(c.bytes_written, 0u) << c.kernel << " in " << c.stage;
    EXPECT_FALSE(c.stage.empty()) << c.kernel << ": every dispatch belongs to a named stage";
  }
  // The convolutions' and products' multiply-adds are the network's arithmetic as
  // network_cost() counts it from the architecture table (the attention's and matching's
  // products included), which shares nothing with the recorder's count. The upsampler's mask
  // convolution counts its convex upsampling too (9 for each of a full-size pixel's 2 values) and
  // the zero rows its tiles' order adds (mask_padding).
  const double counted = static_cast<double>(multiply_adds_of(
      work, {"conv2d", "matmul", "matmul_norm", "matmul_mlp_norm", "flash_attention", "conv2d_convex"}));
  const double expected =
      network_cost(kHeight, kWidth).stream_frame() / 2 + 18.0 * kHeight * kWidth + mask_padding(kHeight, kWidth);
  EXPECT_NEAR(counted, expected, expected * 1e-12);
  expect_within(work, kDirect);

  // Independent ops side by side share a barrier: a wait only before a command that reads what
  // one since the last barrier wrote (or writes what it touched).
  const auto waits_in = [&](std::string_view stage) {
    return std::count_if(work.commands.begin(), work.commands.end(),
                         [&](const DeviceCommand& c) { return c.stage == stage && c.after_barrier; });
  };
  int waits = 0;
  for (const auto& c : work.commands) waits += c.after_barrier ? 1 : 0;
  EXPECT_EQ(waits + 1, work.barriers) << "every barrier but the flow read-back's is before a command";
  // The two ConvBlocks on the 1/2 and 1/4 inputs: first convolutions together, second ones
  // together too (each writes its half of the concatenation and touches nothing else of that
  // buffer), then block_cat_8's two.
  EXPECT_EQ(waits_in("backbone_s8"), 3);
  // Both frames' merges and the context's step by step: the three inputs, the three first
  // convolutions, the three second ones, a barrier a step. Each frame's input is a concatenation
  // of its features and its attended ones upsampled, both parts in one dispatch; so is the
  // context's.
  EXPECT_EQ(waits_in("merge_s8"), 3);
  const auto resamples_in = [&](std::string_view stage) {
    return std::count_if(work.commands.begin(), work.commands.end(),
                         [&](const DeviceCommand& c) { return c.stage == stage && c.kernel == "resample"; });
  };
  EXPECT_EQ(resamples_in("merge_s8"), 3) << "the flow's upsampling is in the 1/16 refinement's last update";

  // Recorded inside other dispatches: each refinement step's update in the next step's
  // correlation (only the last step of each scale keeps its own, which writes the new flow where
  // it goes next too: the 1/8 flow, the upsampler's input), each scale's first step input (the
  // hidden state zeroed, the flow copied) in its first correlation, the attention's BatchNorm in
  // its last LayerNorm, and every LayerNorm in the product before it (the merge's, mlp.2's); the
  // 8-bit frame's conversion and its three poolings in one.
  const Iterations steps;
  EXPECT_EQ(test::dispatches_of(work, "refine_update"), 2);
  // The copies: both frames' tokens stacked for the attention, the upsampler's features into its
  // input (which the direct convolution reads whole). Each attention layer's source lies in its
  // MLP input's first half, never copied; the last LayerNorm writes each frame's tokens apart,
  // and the convex upsampling the flow where the host reads it.
  EXPECT_EQ(test::dispatches_of(work, "copy"), 3);
  EXPECT_EQ(test::dispatches_of(work, "layer_norm"), 0);
  EXPECT_EQ(test::dispatches_of(work, "layer_norm_unstacked"), 0);
  EXPECT_EQ(test::dispatches_of(work, "matmul_norm"), 4);
  EXPECT_EQ(test::dispatches_of(work, "local_correlation"), 0);
  EXPECT_EQ(test::dispatches_of(work, "local_correlation_update"), steps.s16 + steps.s8);
  EXPECT_EQ(test::dispatches_of(work, "channel_affine"), 0);
  EXPECT_EQ(test::dispatches_of(work, "frame_u8"), 0);
  EXPECT_EQ(test::dispatches_of(work, "avgpool2x"), 0);
  EXPECT_EQ(test::dispatches_of(work, "frame_pyramid"), 1);
  // Each attention layer runs both frames in one dispatch (their tokens in one tensor), the
  // matching in a third.
  EXPECT_EQ(test::dispatches_of(work, "flash_attention"), 3);
}

// Winograd F(4×4, 3×3) computes 36 products per 4×4 tile and channel pair where the direct
// convolution computes 144. A layer takes it where that is less work as the products are tiled:
// at 160×128 the 1/8 layers (20×16 pixels) do, the 1/16 ones (10×8) do not. Fused or split, the
// products are the same.
TEST_F(VulkanWork, WinogradComputesFewerMultiplyAdds) {
  constexpr int kW = 160, kH = 128;
  const std::vector<cv::Mat> frames = test::camera_frames(frames_folder_, 2, cv::Size(kW, kH));
  const auto streamed_frame = [&](const char* conv) {
    EXPECT_EQ(setenv("NEUFLOW_VULKAN_CONV", conv, 1), 0);
    FlowSession winograd(model_, {.backend = Backend::vulkan, .device = 0});
    unsetenv("NEUFLOW_VULKAN_CONV");
    winograd.push(test::bgr_view(frames[0]));
    winograd.push(test::bgr_view(frames[1]));
    return winograd.device_work();
  };
  const DeviceWork fused = streamed_frame("winograd");
  const DeviceWork split = streamed_frame("winograd-split");
  print("Winograd at 160x128, fused", fused);
  print("Winograd at 160x128, split", split);
  // The direct convolutions' count without running them: network_cost()'s products (which the
  // direct count equals, as the test above checks) and the kernels both ways share.
  // The steps that end beside their conv3 compute its two delta channels directly (the split
  // form by Winograd, with the rest of conv3) and, but for a scale's last, the next step's
  // correlation with them.
  const long correlated = test::dispatches_of(fused, "winograd_conv_step");
  const long beside = correlated + test::dispatches_of(fused, "winograd_conv_step_end");
  constexpr long long kIn = 96, kPlane = (kH / 8) * (kW / 8), kTiles = (kH / 8 + 3) / 4 * ((kW / 8 + 3) / 4);
  constexpr long long kCorrelation = 81 * kPlane * 128, kDeltaDirect = 2 * 9 * kIn * kPlane,
                      kDeltaWinograd = 36 * 2 * kIn * kTiles;
  const double direct = network_cost(kH, kW).stream_frame() / 2 + 18.0 * kH * kW + mask_padding(kH, kW) +
                        static_cast<double>(multiply_adds_of(fused, {"local_correlation", "local_correlation_update"}) +
                                            correlated * kCorrelation);
  const double ratio = static_cast<double>(fused.multiply_adds()) / direct;
  std::printf("multiply-adds, Winograd over direct: %.3f\n", ratio);
  EXPECT_LE(ratio, kWinogradRatioBudget);
  EXPECT_GT(multiply_adds_of(fused, {"winograd_conv", "winograd_conv_parts"}), 0u);
  const auto split_commands = [](const DeviceWork& work) {
    return std::count_if(work.commands.begin(), work.commands.end(), [](const DeviceCommand& c) {
      return c.kernel == "winograd_input" || c.kernel == "winograd_gemm" || c.kernel == "winograd_output";
    });
  };
  EXPECT_EQ(split_commands(fused), 0);
  EXPECT_EQ(split_commands(split),
            3 * std::count_if(fused.commands.begin(), fused.commands.end(),
                              [](const DeviceCommand& c) { return c.kernel.starts_with("winograd_conv"); }));
  EXPECT_EQ(correlated, Iterations{}.s8 - 1) << "every 1/8 step but the last";
  EXPECT_EQ(beside, Iterations{}.s8) << "and the last, whose update the 1/16 layers (direct here) keep";
  EXPECT_EQ(test::dispatches_of(fused, "local_correlation_update"), Iterations{}.s16 + 1);
  EXPECT_EQ(multiply_adds_of(split, {"winograd_gemm"}),
            multiply_adds_of(fused, {"winograd_conv", "winograd_conv_parts"}) +
                static_cast<std::uint64_t>(beside) * 36 * 66 * kIn * kTiles);
  EXPECT_EQ(split.multiply_adds() + static_cast<std::uint64_t>(beside * kDeltaDirect),
            fused.multiply_adds() + static_cast<std::uint64_t>(beside * kDeltaWinograd));
  // The fused form reads the merges' inputs (both frames' and the context's) and the upsampler's
  // where their parts lie; the split form writes them as concatenations first.
  const auto merge_resamples = [](const DeviceWork& work) {
    return std::count_if(work.commands.begin(), work.commands.end(),
                         [](const DeviceCommand& c) { return c.stage == "merge_s8" && c.kernel == "resample"; });
  };
  EXPECT_EQ(merge_resamples(fused), 0);
  EXPECT_EQ(test::dispatches_of(fused, "winograd_conv_parts"), 4) << "three merges and the upsampler's first layer";
  EXPECT_EQ(merge_resamples(split), 3);
  EXPECT_EQ(fused.copies + 1, split.copies);
  expect_within(fused, kWinograd);
  expect_within(split, kWinogradSplit);
}

// On tensor cores (here their emulated twin, which runs the same commands) the Winograd layers
// are one dispatch each too (winograd_conv_fragments.comp): the tiles and products stay in the
// workgroup, where the split form writes and reads them back in fp32.
TEST_F(VulkanWork, OnTensorCoresAWinogradLayerIsOneDispatch) {
  if (!list_gpu_devices().at(0).fp16) GTEST_SKIP() << "Vulkan device 0 has no fp16: the fragments multiply fp16";
  constexpr int kW = 160, kH = 128;
  const std::vector<cv::Mat> frames = test::camera_frames(frames_folder_, 2, cv::Size(kW, kH));
  const auto streamed_frame = [&](const char* products, const char* conv) {
    EXPECT_EQ(setenv("NEUFLOW_VULKAN_PRODUCTS", products, 1), 0);
    EXPECT_EQ(setenv("NEUFLOW_VULKAN_CONV", conv, 1), 0);
    FlowSession s(model_, {.backend = Backend::vulkan, .device = 0, .precision = Precision::fp16});
    unsetenv("NEUFLOW_VULKAN_PRODUCTS");
    unsetenv("NEUFLOW_VULKAN_CONV");
    s.push(test::bgr_view(frames[0]));
    s.push(test::bgr_view(frames[1]));
    return s.device_work();
  };
  const DeviceWork scalar = streamed_frame("scalar", "winograd");
  const DeviceWork fused = streamed_frame("twin", "winograd");
  const DeviceWork split = streamed_frame("twin", "winograd-split");
  print("fp16 Winograd at 160x128, scalar", scalar);
  print("fp16 Winograd at 160x128, tensor cores (twin), fused", fused);
  print("fp16 Winograd at 160x128, tensor cores (twin), split", split);
  const long beside = test::dispatches_of(fused, "winograd_conv_step_coopmat_twin") +
                      test::dispatches_of(fused, "winograd_conv_step_end_coopmat_twin");
  const long layers = test::dispatches_of(fused, "winograd_conv_coopmat_twin") +
                      test::dispatches_of(fused, "winograd_conv_parts_coopmat_twin") + beside;
  EXPECT_EQ(test::dispatches_of(fused, "winograd_conv_parts_coopmat_twin"),
            test::dispatches_of(scalar, "winograd_conv_parts"));
  EXPECT_EQ(beside,
            test::dispatches_of(scalar, "winograd_conv_step") + test::dispatches_of(scalar, "winograd_conv_step_end"));
  EXPECT_EQ(layers,
            test::dispatches_of(scalar, "winograd_conv") + test::dispatches_of(scalar, "winograd_conv_parts") + beside);
  EXPECT_GT(layers, 0);
  EXPECT_EQ(fused.dispatches, scalar.dispatches);
  EXPECT_EQ(fused.barriers, scalar.barriers);
  EXPECT_EQ(split.dispatches, fused.dispatches + 2 * layers + 3 + beside)
      << "the split form writes the merges' inputs, and ends each step after its conv3";
  EXPECT_EQ(fused.multiply_adds(), scalar.multiply_adds());
  expect_within(fused, kWinogradFragments);
}

TEST_F(VulkanWork, APipelinedFrameTakesOneSubmissionAndOneWait) {
  FlowSession gpu(model_, {.backend = Backend::vulkan, .device = 0});
  gpu.submit(frame(0));
  gpu.submit(frame(1));
  gpu.take();  // the first frame: no pair
  gpu.submit(frame(2));
  ASSERT_TRUE(gpu.take().has_value());
  const DeviceWork& work = gpu.device_work();
  EXPECT_EQ(work.submissions, 1);
  EXPECT_EQ(work.host_waits, 1);
  FlowSession pushed(model_, {.backend = Backend::vulkan, .device = 0});
  pushed.push(frame(1));
  pushed.push(frame(2));
  EXPECT_EQ(work.dispatches, pushed.device_work().dispatches) << "the same commands in one submission";
}

TEST_F(VulkanWork, Fp16HalvesTheTensorsBytes) {
  if (!list_gpu_devices().at(0).fp16) GTEST_SKIP() << "Vulkan device 0 has no fp16";
  FlowSession fp32(model_, {.backend = Backend::vulkan, .device = 0});
  FlowSession fp16(model_, {.backend = Backend::vulkan, .device = 0, .precision = Precision::fp16});
  for (auto* s : {&fp32, &fp16}) {
    s->push(frame(0));
    s->push(frame(1));
  }
  const DeviceWork &a = fp32.device_work(), &b = fp16.device_work();
  // In fp16 each attention layer's MLP and the LayerNorm after it are one dispatch
  // (matmul_mlp_norm: its hidden layer fits in workgroup memory only in 16 bits), two in fp32.
  EXPECT_EQ(test::dispatches_of(b, "matmul_mlp_norm"), 2);
  EXPECT_EQ(a.dispatches, b.dispatches + 2);
  EXPECT_EQ(a.multiply_adds(), b.multiply_adds());
  // Every tensor in 16 bits, command by command, except where the 8-bit frame is read, the
  // Winograd tiles and products, which stay fp32, and the flow handed to the host, fp32 as the
  // host takes it.
  ASSERT_EQ(a.commands.size(), b.commands.size() + 2);
  int halved = 0;
  for (std::size_t i = 0, j = 0; j < b.commands.size(); ++i, ++j) {
    const DeviceCommand &x = a.commands[i], &y = b.commands[j];
    if (y.kernel == "matmul_mlp_norm") {
      // The fp32 pair: the hidden layer's product, written, then read by the product whose
      // LayerNorm the epilogue computes.
      const DeviceCommand& next = a.commands[++i];
      EXPECT_EQ(x.kernel, "matmul");
      EXPECT_EQ(next.kernel, "matmul_norm");
      EXPECT_EQ(next.bytes_written, 2 * y.bytes_written);
      EXPECT_EQ(x.multiply_adds + next.multiply_adds, y.multiply_adds);
      continue;
    }
    ASSERT_EQ(x.kernel, scalar_kernel(y.kernel));
    if (x.kernel == "frame_u8" || x.kernel == "frame_pyramid" || x.kernel.starts_with("winograd_")) continue;
    EXPECT_EQ(x.bytes_read, 2 * y.bytes_read) << x.kernel << " in " << x.stage;
    if (x.kernel == "conv2d_convex") {
      EXPECT_EQ(x.bytes_written, y.bytes_written);
      EXPECT_EQ(y.bytes_written, 2LL * kHeight * kWidth * static_cast<long long>(sizeof(float)));
      EXPECT_EQ(test::dispatches_of(b, "convex_upsample"), 0) << "the mask is never written";
    } else {
      EXPECT_EQ(x.bytes_written, 2 * y.bytes_written) << x.kernel << " in " << x.stage;
    }
    ++halved;
  }
  EXPECT_GT(halved, 80);
}

TEST_F(VulkanWork, AnObservedPassIsNotCounted) {
  FlowSession gpu(model_, {.backend = Backend::vulkan, .device = 0});
  gpu.set_observer([](const StageTensor&) {});
  gpu.push(frame(0));
  gpu.push(frame(1));
  EXPECT_EQ(gpu.device_work().dispatches, 0);
  FlowSession cpu(model_, {.backend = Backend::cpu});
  cpu.push(frame(0));
  cpu.push(frame(1));
  EXPECT_TRUE(cpu.device_work().commands.empty());
}

// The scalar products' tiles at 1024×448 (NEUFLOW_VULKAN_GEMM_TILE=auto): on a GPU the largest
// whose grid keeps 128 workgroups, else the smallest; on a CPU device one workgroup a core.
TEST(GemmTile, ALayerTakesTheLargestTileThatKeepsTheDeviceBusy) {
  using vulkan::gemm_tile_for;
  const vulkan::GemmTiles gpu{0, vulkan::kGpuWideGrid}, cpu{0, 2};
  // The upsampler's 1×1 mask layer, 512 → 576 at 128×56: 5 × 56 tiles of 128×128.
  EXPECT_EQ(gemm_tile_for(576, 128 * 56, 1, gpu), vulkan::kGemmTile128);
  // The 8×8 stride-8 convolution, 3 → 128 at 128×56: one row of 128 tiles is 56, 64×64 gives 224.
  EXPECT_EQ(gemm_tile_for(128, 128 * 56, 1, gpu), vulkan::kGemmTile64);
  EXPECT_EQ(gemm_tile_for(128, 128 * 56, 1, cpu), vulkan::kGemmTile128);
  // The backbone's 1/16 merge, 768 → 128 at 64×28: 56 tiles of 64×64, 224 of 32×32.
  EXPECT_EQ(gemm_tile_for(128, 64 * 28, 1, gpu), vulkan::kGemmTile32);
  // The split Winograd's 36 products of a refinement layer (96 channels, 32 × 14 tiles).
  EXPECT_EQ(gemm_tile_for(96, 32 * 14, 36, gpu), vulkan::kGemmTile128);
  // On a CPU device a product of one 128×128 tile takes 64×64, and of one 64×64 tile 32×32.
  EXPECT_EQ(gemm_tile_for(128, 128, 1, cpu), vulkan::kGemmTile64);
  EXPECT_EQ(gemm_tile_for(64, 64, 1, cpu), vulkan::kGemmTile32);
  // A tile asked for is taken whatever the grid.
  EXPECT_EQ(gemm_tile_for(8, 8, 1, {128, vulkan::kGpuWideGrid}), vulkan::kGemmTile128);
  EXPECT_EQ(gemm_tile_for(4096, 4096, 1, {32, 2}), vulkan::kGemmTile32);
  EXPECT_EQ(vulkan::kGemmTile128.rows(), 128);
  EXPECT_EQ(vulkan::kGemmTile32.columns(), 32);
}

}  // namespace
}  // namespace neuflow::model
