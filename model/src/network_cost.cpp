#include "neuflow/model/network_cost.hpp"

namespace neuflow::model {

namespace {

double conv(int out_h, int out_w, int out_c, int in_c, int k) {
  return 2.0 * out_h * out_w * out_c * in_c * k * k;
}

double refine(int h, int w, int inter) {
  return conv(h, w, 128, 212, 3) + conv(h, w, inter, 128, 3) + 5 * conv(h, w, inter, inter, 3) +
         conv(h, w, 66, inter, 3);
}

}  // namespace

NetworkCost network_cost(int height, int width, const Iterations& it) {
  const int h8 = height / 8, w8 = width / 8, h16 = height / 16, w16 = width / 16;
  const double l = static_cast<double>(h16) * w16;
  NetworkCost c;
  c.backbone = conv(h8, w8, 256, 3, 8) + conv(h8, w8, 256, 256, 3) + conv(h8, w8, 128, 3, 6) +
               conv(h8, w8, 128, 128, 3) + conv(h8, w8, 192, 384, 3) + conv(h8, w8, 192, 192, 3) +
               conv(h16, w16, 128, 3, 6) + conv(h16, w16, 128, 128, 3) + conv(h16, w16, 128, 192, 6) +
               conv(h16, w16, 128, 128, 3) + conv(h16, w16, 190, 256, 3) + conv(h16, w16, 190, 190, 3);
  c.upsample_features = conv(h8, w8, 128, 3, 8) + conv(h8, w8, 128, 128, 3);
  // Per layer and frame: q, k, v, merge projections; scores and weighted sum; the MLP.
  const double layer = 2 * l * 192 * 192 * 4 + 2 * l * l * 192 * 2 + 2 * l * 384 * 384 + 2 * l * 384 * 192;
  c.cross_attention = 4 * layer;
  c.global_matching = 2 * l * l * 128 + 2 * l * l * 2;
  c.refine_s16 = it.s16 * refine(h16, w16, 128);
  c.merge_s8 = 2 * (conv(h8, w8, 128, 256, 3) + conv(h8, w8, 128, 128, 3)) + conv(h8, w8, 64, 128, 3) +
               conv(h8, w8, 64, 64, 3);
  c.refine_s8 = it.s8 * refine(h8, w8, 96);
  c.upsampler = conv(h8, w8, 256, 130, 3) + conv(h8, w8, 512, 256, 3) + conv(h8, w8, 576, 512, 1);
  return c;
}

}  // namespace neuflow::model
