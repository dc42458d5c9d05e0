// The convex upsampling as the epilogue of the product that computes its mask (the upsampler's
// 1×1 conv3, IMPLICIT_CONV with CONVEX_UPSAMPLE), so that the 576 mask channels at 1/8 are never
// written: a workgroup's BM rows of the product are the 9 logits of BM / 9 subpixels (the
// filters' rows reordered at upload, DeviceWeights::convex_mask: tile t holds subpixels
// t·(BM / 9) on, row g·9 + k their neighbour k; rows past them zero), its BN columns 1/8 pixels.
// The tile's sums plus bias go to workgroup memory; then each (subpixel, pixel) of it is
// convex_upsample.comp's arithmetic: the flow's full-size pixel (8y + a, 8x + b), interleaved
// fp32 into binding 2 (the host's read-back buffer), the 1/8 flow from binding 3 at p.add_off.
// Needs BM, BN, the bindings and the push constants (conv2d_params.h) declared.

const int CONVEX_GROUPS = BM / 9;  // subpixels a tile
shared float logits[BM][BN + 1];

void convex_store(int m, int n, float sum) {
  const int row0 = int(gl_WorkGroupID.y) * BM, col0 = int(gl_WorkGroupID.x) * BN;
  logits[m - row0][n - col0] = p.alpha * sum + (p.bias_off >= 0 ? float(a_data[p.bias_off + m]) : 0.0);
}

// After every invocation's convex_store() and a barrier.
void convex_upsample_tile(int tid, int invocations) {
  const int plane8 = p.out_h * p.out_w;
  const int W = 8 * p.out_w;
  const int col0 = int(gl_WorkGroupID.x) * BN, s0 = int(gl_WorkGroupID.y) * CONVEX_GROUPS;
  for (int at = tid; at < CONVEX_GROUPS * BN; at += invocations) {
    const int g = at / BN, n = at - (at / BN) * BN;
    const int pix = col0 + n, s = s0 + g;
    if (pix >= plane8 || s >= 64) continue;
    const int y = pix / p.out_w, x = pix - y * p.out_w;
    float m = -3.402823e38;
    for (int k = 0; k < 9; ++k) m = max(m, logits[g * 9 + k][n]);
    float sum = 0.0, u = 0.0, v = 0.0;
    for (int k = 0; k < 9; ++k) {
      const float e = exp(logits[g * 9 + k][n] - m);
      const int yy = y + k / 3 - 1, xx = x + k % 3 - 1;
      sum += e;
      if (yy >= 0 && yy < p.out_h && xx >= 0 && xx < p.out_w) {
        u += e * float(d_data[p.add_off + yy * p.out_w + xx]);
        v += e * float(d_data[p.add_off + plane8 + yy * p.out_w + xx]);
      }
    }
    const int i = (8 * y + s / 8) * W + 8 * x + s % 8;
    c_data[2 * i] = 8.0 * u / sum;
    c_data[2 * i + 1] = 8.0 * v / sum;
  }
}
