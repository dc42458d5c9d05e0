// NeuFlow-V2's local correlation of a block of 16 pixels, shared by local_correlation.comp and
// the refinement step's end beside its conv3 (winograd_conv.comp, winograd_conv_fragments.comp
// with STEP_CORRELATION). Per pixel, dot products with the 10×10 integer neighbours of
// floor(p + flow) in frame 1, blended with the shared bilinear weights into the 9×9 window.
// Channel i*9 + j holds offset (dx = i - 4, dy = j - 4); positions outside frame 1 read as zero.
// Planar tensors throughout. Invocation (lx, j) of a block: pixel lx, neighbour row j; row j sums
// the 10 dot products of its neighbour row (10 live accumulators, not 100), the rows meet in
// workgroup memory, and rows 0-8 then blend and write the window's row j for their pixel.
// Invocations with j >= 10 only meet the barriers.
//
// The including shader declares f0, f1, dst (the correlation's output) and flow (VALUE
// buffers), and CORRELATION_SCRATCH(i), 120 floats a pixel of workgroup memory. With APPLY_UPDATE the
// block also ends the refinement's previous step from conv3's output (`update`): the flow plus
// its delta, the clamped hidden state into the step input; with STEP_DELTA it computes conv3's
// delta itself, from conv3's input (`src`) and filters (`u`), where the including shader's
// other workgroups compute the hidden state. Either way the new flow is written back (and into
// the step input's flow channels) once every invocation of the block has read it. With
// neither, and with update_off < 0 under APPLY_UPDATE (a scale's first correlation), the flow
// is read as it is. With STEP_UPDATE_ONLY (and STEP_DELTA) there is no correlation: a scale's
// last step ends (update_block), its new flow also resampled into `resampled` (refine_update.comp's
// arithmetic) where the including shader declares it.

// CORRELATION_PIXELS: the pixels of a block, as the including shader's invocations divide into
// them (16 for local_correlation.comp's 16 × 10; 19 for 192 invocations: 190 busy).
const int CORR_R = 4, CORR_WIN = 9, CORR_N = 10, CORR_PIXELS = CORRELATION_PIXELS;

struct Correlation {
  int h, w, channels, f0_off, f1_off, flow_off, out_off;
  int update_off;            // APPLY_UPDATE: conv3's output; < 0: none (the step input's first values)
  int hidden_off;            // APPLY_UPDATE: the step input's hidden state
  int flow_copy_off;         // APPLY_UPDATE, STEP_DELTA: the step input's flow
  int in_c, in_off;          // STEP_DELTA: conv3's input
  int delta_w_off, delta_bias_off;  // STEP_DELTA: conv3's first two filters (OIHW) and biases
  int resampled_off, factor;        // STEP_UPDATE_ONLY: the new flow upsampled by factor (< 0: not)
  float scale;                      // ... and scaled
};

// [row j][column i][pixel]: the dot product with (bx + i, by + j); then 2 × [row j][pixel]: the
// rows' parts of the delta.
#define CORR_SUM(j, i, lx) CORRELATION_SCRATCH(((j) * CORR_N + (i)) * CORR_PIXELS + (lx))
#define CORR_DELTA(d, j, lx) CORRELATION_SCRATCH(CORR_N * CORR_N * CORR_PIXELS + ((d) * CORR_N + (j)) * CORR_PIXELS + (lx))

#ifdef STEP_DELTA
// Row j's part of conv3's output channel d (a 3×3 convolution with padding 1) at (y, x): input
// channels j, j + 10, ...
float delta_part(const Correlation q, int d, int j, int y, int x) {
  const int plane = q.h * q.w;
  float s = 0.0;
  for (int c = j; c < q.in_c; c += CORR_N) {
    const int wbase = q.delta_w_off + (d * q.in_c + c) * 9;
    for (int ky = 0; ky < 3; ++ky) {
      const int yy = y + ky - 1;
      if (yy < 0 || yy >= q.h) continue;
      for (int kx = 0; kx < 3; ++kx) {
        const int xx = x + kx - 1;
        if (xx >= 0 && xx < q.w) s = fma(float(u[wbase + ky * 3 + kx]), float(src[q.in_off + c * plane + yy * q.w + xx]), s);
      }
    }
  }
  return s;
}

// The flow (vx, vy) of pixel pix plus conv3's delta there, rounded as conv3 would have stored it;
// invocation row j sums its part. Every invocation of the workgroup calls it (a barrier).
void add_delta(const Correlation q, int pix, int lx, int j, bool row, inout float vx, inout float vy) {
  if (row) {
    const int y = pix / q.w, x = pix - y * q.w;
    CORR_DELTA(0, j, lx) = delta_part(q, 0, j, y, x);
    CORR_DELTA(1, j, lx) = delta_part(q, 1, j, y, x);
  }
  barrier();
  if (row) {
    float s0 = float(u[q.delta_bias_off]), s1 = float(u[q.delta_bias_off + 1]);
    for (int r = 0; r < CORR_N; ++r) {
      s0 += CORR_DELTA(0, r, lx);
      s1 += CORR_DELTA(1, r, lx);
    }
    vx += float(VALUE(s0));
    vy += float(VALUE(s1));
  }
}
#endif

#ifdef STEP_UPDATE_ONLY
// A scale's last step's end for pixels block ..: the new flow into the flow, the step input's
// flow channels and, upsampled and scaled, `resampled`.
void update_block(const Correlation q, int block, int lx, int j) {
  const int plane = q.h * q.w, pix = block + lx;
  const bool row = j < CORR_N && pix < plane;
  float v[2] = float[2](0.0, 0.0);
  if (row) {
    v[0] = float(flow[q.flow_off + pix]);
    v[1] = float(flow[q.flow_off + plane + pix]);
  }
  add_delta(q, pix, lx, j, row, v[0], v[1]);  // every row has read the flow before its barrier
  if (row && j == 0) {
    const int y = pix / q.w, x = pix - y * q.w, wide = q.w * q.factor, big = plane * q.factor * q.factor;
    for (int d = 0; d < 2; ++d) {
      flow[q.flow_off + d * plane + pix] = VALUE(v[d]);
      dst[q.flow_copy_off + d * plane + pix] = VALUE(v[d]);
      if (q.resampled_off < 0) continue;
      for (int dy = 0; dy < q.factor; ++dy) {
        for (int dx = 0; dx < q.factor; ++dx) {
          resampled[q.resampled_off + d * big + (y * q.factor + dy) * wide + x * q.factor + dx] = VALUE(v[d] * q.scale);
        }
      }
    }
  }
  barrier();  // the next block writes the scratch again
}
#else

// Pixels block .. block + CORR_PIXELS - 1, as invocation (lx, j); every invocation of the workgroup calls it
// with the same block, as it meets barriers.
void correlate_block(const Correlation q, int block, int lx, int j) {
  const int plane = q.h * q.w;
  const float norm = inversesqrt(float(q.channels));
  const int pix = block + lx;
  const bool row = j < CORR_N && pix < plane;
  const int y = pix / q.w, x = pix - y * q.w;
  float ax = 0.0, ay = 0.0;
  float d[CORR_N];
  for (int i = 0; i < CORR_N; ++i) d[i] = 0.0;
  VALUE fx = VALUE(0.0), fy = VALUE(0.0);
  if (row) {
    fx = flow[q.flow_off + pix];
    fy = flow[q.flow_off + plane + pix];
  }
#ifdef STEP_DELTA
  float vx = float(fx), vy = float(fy);
  add_delta(q, pix, lx, j, row, vx, vy);
  fx = VALUE(vx);
  fy = VALUE(vy);
#endif
#ifdef APPLY_UPDATE
  if (row) {
    if (q.update_off >= 0) {
      fx = VALUE(float(fx) + float(update[q.update_off + pix]));
      fy = VALUE(float(fy) + float(update[q.update_off + plane + pix]));
    }
    for (int c = j; c < 64; c += CORR_N) {
      dst[q.hidden_off + c * plane + pix] =
          q.update_off >= 0 ? VALUE(clamp(float(update[q.update_off + (2 + c) * plane + pix]), -4.0, 4.0)) : VALUE(0.0);
    }
  }
#endif
  if (row) {
    const float px = float(x) + float(fx);
    const float py = float(y) + float(fy);
    if (abs(px) < 1e6 && abs(py) < 1e6) {  // far outside (or not a number): all zero
      const float fx0 = floor(px), fy0 = floor(py);
      ax = px - fx0;
      ay = py - fy0;
      const int bx = int(fx0) - CORR_R, qy = int(fy0) - CORR_R + j;
      if (qy >= 0 && qy < q.h) {
        for (int c = 0; c < q.channels; ++c) {
          const float a = float(f0[q.f0_off + c * plane + pix]) * norm;
          const int frow = q.f1_off + c * plane + qy * q.w;
          for (int i = 0; i < CORR_N; ++i) {
            const int qx = bx + i;
            if (qx >= 0 && qx < q.w) d[i] = fma(a, float(f1[frow + qx]), d[i]);
          }
        }
      }
    }
    for (int i = 0; i < CORR_N; ++i) CORR_SUM(j, i, lx) = d[i];
  }
  barrier();
#if defined(APPLY_UPDATE) || defined(STEP_DELTA)
  // Every invocation of this pixel has read its flow (before the barrier).
  if (row && j == 0) {
#ifdef APPLY_UPDATE
    const bool updated = q.update_off >= 0;
#else
    const bool updated = true;
#endif
    if (updated) {
      flow[q.flow_off + pix] = fx;
      flow[q.flow_off + plane + pix] = fy;
    }
    dst[q.flow_copy_off + pix] = fx;
    dst[q.flow_copy_off + plane + pix] = fy;
  }
#endif
  if (row && j < CORR_WIN) {
    const float w00 = (1.0 - ax) * (1.0 - ay), w10 = ax * (1.0 - ay), w01 = (1.0 - ax) * ay, w11 = ax * ay;
    for (int i = 0; i < CORR_WIN; ++i) {
      dst[q.out_off + (i * CORR_WIN + j) * plane + pix] =
          VALUE(w00 * CORR_SUM(j, i, lx) + w10 * CORR_SUM(j, i + 1, lx) + w01 * CORR_SUM(j + 1, i, lx) +
                w11 * CORR_SUM(j + 1, i + 1, lx));
    }
  }
  barrier();  // the next block writes the scratch again
}
#endif
