// The cost model, derived from the architecture table, against the arithmetic written out by
// hand from shared/docs/neuflow-v2-network.md, stage by stage.
#include <gtest/gtest.h>

#include "neuflow/model/architecture.hpp"
#include "neuflow/model/network_cost.hpp"

namespace neuflow::model {
namespace {

double conv(int out_h, int out_w, int out_c, int in_c, int k) { return 2.0 * out_h * out_w * out_c * in_c * k * k; }

// `iterations` steps: conv1's share of the context and radius channels (65 of its 212 inputs)
// once, the rest at every step.
double refine(int h, int w, int inter, int iterations) {
  return conv(h, w, 128, 65, 3) + iterations * (conv(h, w, 128, 147, 3) + conv(h, w, inter, 128, 3) +
                                                5 * conv(h, w, inter, inter, 3) + conv(h, w, 66, inter, 3));
}

TEST(NetworkCost, EveryStageMatchesTheArithmeticByHand) {
  for (const auto& [height, width] : {std::pair{432, 768}, std::pair{256, 320}, std::pair{448, 1024}}) {
    const Iterations it{2, 5};
    const int h8 = height / 8, w8 = width / 8, h16 = height / 16, w16 = width / 16;
    const double l = static_cast<double>(h16) * w16;
    const NetworkCost c = network_cost(height, width, it);
    EXPECT_DOUBLE_EQ(c.backbone, conv(h8, w8, 256, 3, 8) + conv(h8, w8, 256, 256, 3) + conv(h8, w8, 128, 3, 6) +
                                     conv(h8, w8, 128, 128, 3) + conv(h8, w8, 192, 384, 3) + conv(h8, w8, 192, 192, 3) +
                                     conv(h16, w16, 128, 3, 6) + conv(h16, w16, 128, 128, 3) +
                                     conv(h16, w16, 128, 192, 6) + conv(h16, w16, 128, 128, 3) +
                                     conv(h16, w16, 190, 256, 3) + conv(h16, w16, 190, 190, 3));
    EXPECT_DOUBLE_EQ(c.upsample_features, conv(h8, w8, 128, 3, 8) + conv(h8, w8, 128, 128, 3));
    const double layer = 2 * l * 192 * 192 * 4 + 2 * l * l * 192 * 2 + 2 * l * 384 * 384 + 2 * l * 384 * 192;
    EXPECT_DOUBLE_EQ(c.cross_attention, 4 * layer);  // two layers, both frames
    EXPECT_DOUBLE_EQ(c.global_matching, 2 * l * l * 128 + 2 * l * l * 2);
    EXPECT_DOUBLE_EQ(c.refine_s16, refine(h16, w16, 128, it.s16));
    EXPECT_DOUBLE_EQ(c.merge_s8, 2 * (conv(h8, w8, 128, 256, 3) + conv(h8, w8, 128, 128, 3)) +
                                     conv(h8, w8, 64, 128, 3) + conv(h8, w8, 64, 64, 3));
    EXPECT_DOUBLE_EQ(c.refine_s8, refine(h8, w8, 96, it.s8));
    EXPECT_DOUBLE_EQ(c.upsampler, conv(h8, w8, 256, 130, 3) + conv(h8, w8, 512, 256, 3) + conv(h8, w8, 576, 512, 1));
  }
}

TEST(NetworkCost, LayersAreFoundByName) {
  EXPECT_EQ(neuflow_v2_layer("refine_s8.conv3").out, 66);
  EXPECT_EQ(neuflow_v2_layer("refine_s8.conv3").in, 96);
  EXPECT_TRUE(neuflow_v2_layer("refine_s8.conv3").bias);
  EXPECT_EQ(neuflow_v2_layer("backbone.block_8_1.conv1").kernel, 8);
  EXPECT_THROW(neuflow_v2_layer("refine_s8.conv4"), std::out_of_range);
}

}  // namespace
}  // namespace neuflow::model
