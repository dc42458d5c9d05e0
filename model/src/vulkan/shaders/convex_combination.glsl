// The convex upsampling's arithmetic for one full-size pixel, shared by convex_upsample.comp and
// the mask product's epilogue (convex_upsample_tile.glsl): 8 · Σ_k softmax_k(logit[k]) ·
// flow8[3×3 neighbour k of the 1/8 pixel (y, x)], zero outside. Needs CONVEX_FLOW8(i): value i
// of the planar [2][h8·w8] 1/8 flow.

vec2 convex_flow(float logit[9], int y, int x, int h8, int w8) {
  float m = -3.402823e38;
  for (int k = 0; k < 9; ++k) m = max(m, logit[k]);
  float sum = 0.0, u = 0.0, v = 0.0;
  for (int k = 0; k < 9; ++k) {
    const float e = exp(logit[k] - m);
    const int yy = y + k / 3 - 1, xx = x + k % 3 - 1;
    sum += e;
    if (yy >= 0 && yy < h8 && xx >= 0 && xx < w8) {
      u += e * CONVEX_FLOW8(yy * w8 + xx);
      v += e * CONVEX_FLOW8(h8 * w8 + yy * w8 + xx);
    }
  }
  return vec2(8.0 * u / sum, 8.0 * v / sum);
}
