// The convex upsampling as the epilogue of the product that computes its mask (the upsampler's
// 1×1 conv3, IMPLICIT_CONV with CONVEX_UPSAMPLE), so that the 576 mask channels at 1/8 are never
// written: a workgroup's BM rows of the product are the 9 logits of BM / 9 subpixels (the
// filters' rows reordered at upload, DeviceWeights::convex_mask: tile t holds subpixels
// t·(BM / 9) on, row g·9 + k their neighbour k; rows past them zero), its BN columns 1/8 pixels.
// The tile's sums plus bias go to workgroup memory; then each (subpixel, pixel) of it is
// convex_combination.glsl's arithmetic: the flow's full-size pixel (8y + a, 8x + b), interleaved
// fp32 into binding 2 (the host's read-back buffer), the 1/8 flow from binding 3 at p.add_off.
// Needs BM, BN, the bindings and the push constants (conv2d_params.h) declared.

#define CONVEX_FLOW8(i) float(d_data[p.add_off + (i)])
#include "convex_combination.glsl"

// The product runs in 64×64 tiles only (the rows' order is made for them, and the recorder asks
// for no other), so the logits' array has a size of plain constants: Ubuntu 22.04's validation
// layer misjudges arrays sized from the tile's specialization constants (it reported 68-84 KB of
// shared memory for 16 KB), and counts the tiles' staging as 16.6 KB. So the logits are kept in
// the tensors' precision (as the mask tensor held them when it was written), and half of the
// tile's columns at a time (convex_half): 8 KB in fp32, 4 KB in fp16, under lavapipe's 32 KiB
// by that count too.
const int CONVEX_GROUPS = 7, CONVEX_ROWS = 9 * CONVEX_GROUPS, CONVEX_COLUMNS = 32, CONVEX_STRIDE = CONVEX_COLUMNS + 1;
shared VALUE logits[CONVEX_ROWS * CONVEX_STRIDE];  // [row][column]; the tile's zero rows dropped
int convex_half = 0;                               // which half of the tile's columns is in logits

void convex_store(int m, int n, float sum) {
  const int row = m - int(gl_WorkGroupID.y) * BM;
  const int col = n - int(gl_WorkGroupID.x) * BN - CONVEX_COLUMNS * convex_half;
  if (row < CONVEX_ROWS && col >= 0 && col < CONVEX_COLUMNS) {
    logits[row * CONVEX_STRIDE + col] =
        VALUE(p.alpha * sum + (p.bias_off >= 0 ? float(a_data[p.bias_off + m]) : 0.0));
  }
}

// After every invocation's convex_store() of the half and a barrier.
void convex_upsample_tile(int tid, int invocations) {
  const int plane8 = p.out_h * p.out_w;
  const int W = 8 * p.out_w;
  const int col0 = int(gl_WorkGroupID.x) * BN + CONVEX_COLUMNS * convex_half;
  const int s0 = int(gl_WorkGroupID.y) * CONVEX_GROUPS;
  for (int at = tid; at < CONVEX_GROUPS * CONVEX_COLUMNS; at += invocations) {
    const int g = at / CONVEX_COLUMNS, n = at % CONVEX_COLUMNS;
    const int pix = col0 + n, s = s0 + g;
    if (pix >= plane8 || s >= 64) continue;
    const int y = pix / p.out_w, x = pix - y * p.out_w;
    float logit[9];
    for (int k = 0; k < 9; ++k) logit[k] = float(logits[(g * 9 + k) * CONVEX_STRIDE + n]);
    const vec2 f = convex_flow(logit, y, x, p.out_h, p.out_w);
    const int i = (8 * y + s / 8) * W + 8 * x + s % 8;
    c_data[2 * i] = f.x;
    c_data[2 * i + 1] = f.y;
  }
}
