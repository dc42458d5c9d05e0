// LayerNorm as a product's epilogue (LAYER_NORM, matmul_norm_params.h): the workgroup's tile
// holds every row of its columns (a token's channels), so it normalizes each column where it
// computed it, and the product's output never goes through global memory. The products are
// rounded to the stored type in workgroup memory (`normed`), as the product would have stored
// them, and the statistics are summed in layer_norm.comp's order (16 lanes a token, each every
// 16th channel, the lanes' sums in lane order; mean, then variance about it): the fused dispatch
// computes what the product and the LayerNorm computed apart.
// Needs BM, BN (the tile), the bindings a_data (bias, gamma, beta, scale, shift), d_data (the
// residual), c_data and out2 (the outputs), and gemm_operands.glsl.
const int NORM_LANES = 16;
#ifdef MLP
#define normed mlp_hidden  // free again once the second product has read it
#else
shared VALUE normed[kMatmulNormChannels * 16];  // [row][column of the tile]
#endif
// Sized as the tile is, 192×16 (BM × BN), in plain constants: a validation layer may size
// arrays by the specialization constants' defaults, or misjudge them.
shared float norm_partial[NORM_LANES * 16];
shared float norm_mean[16], norm_inv[16];

// C[m][n] from its sum of products, before the LayerNorm: scale, bias and activation.
void norm_stage(int m, int n, float sum) {
  if (m >= gemm_m() || n >= gemm_n()) return;
#ifdef MLP
  const int bias = p.bias2_off, act = p.act2;
#else
  const int bias = p.bias_off, act = p.act;
#endif
  float v = p.alpha * sum;
  if (bias >= 0) v += float(a_data[bias + m]);
  normed[m * BN + n - int(gl_WorkGroupID.x) * BN] = VALUE(activate(v, act));
}

#ifdef MLP
// The first product's C[m][n] into the hidden layer (phase 0), the second's for the LayerNorm.
void mlp_store(int m, int n, float sum) {
  if (mlp_phase == 1) {
    norm_stage(m, n, sum);
    return;
  }
  if (m >= gemm_m() || n >= gemm_n()) return;
  float v = p.alpha * sum;
  if (p.bias_off >= 0) v += float(a_data[p.bias_off + m]);
  mlp_hidden[m * BN + n - int(gl_WorkGroupID.x) * BN] = VALUE(activate(v, p.act));
}
#endif

// Each token's partial sums of x (or of (x - mean)² where `centred`) into norm_partial, then
// their totals divided by the channels into norm_mean (centred: the inverse deviation into
// norm_inv).
void norm_statistic(int tid, int invocations, bool centred) {
  const int dim = gemm_m();
  for (int pair = tid; pair < NORM_LANES * BN; pair += invocations) {
    const int token = pair % BN, lane = pair / BN;
    float s = 0.0;
    for (int c = lane; c < dim; c += NORM_LANES) {
      const float x = float(normed[c * BN + token]);
      if (centred) {
        const float d = x - norm_mean[token];
        s += d * d;
      } else {
        s += x;
      }
    }
    norm_partial[lane * BN + token] = s;
  }
  barrier();
  for (int token = tid; token < BN; token += invocations) {
    float s = 0.0;
    for (int l = 0; l < NORM_LANES; ++l) s += norm_partial[l * BN + token];
    if (centred) {
      norm_inv[token] = inversesqrt(s / float(dim) + 1e-5);
    } else {
      norm_mean[token] = s / float(dim);
    }
  }
  barrier();
}

// After every norm_stage of the tile: the LayerNorm of its columns, written out.
void layer_norm_tile(int tid, int invocations) {
  barrier();
  norm_statistic(tid, invocations, false);
  norm_statistic(tid, invocations, true);
  const int col0 = int(gl_WorkGroupID.x) * BN, dim = gemm_m();
  for (int e = tid; e < dim * BN; e += invocations) {
    const int c = e / BN, token = e - c * BN, t = col0 + token;
    if (t >= gemm_n()) continue;
    float o = (float(normed[e]) - norm_mean[token]) * norm_inv[token] * float(a_data[p.gamma_off + c]) +
              float(a_data[p.beta_off + c]);
    if (p.res_off >= 0) o += float(d_data[p.res_off + c * gemm_n() + t]);
    if (p.scale_off >= 0) o = o * float(a_data[p.scale_off + c]) + float(a_data[p.shift_off + c]);
    if (p.split <= 0) {
      c_data[p.c_off + c * p.c_rs + t * p.c_cs] = VALUE(o);
    } else if (t < p.split) {
      c_data[p.c_off + c * p.split + t] = VALUE(o);
    } else {
      out2[p.out2_off + c * p.split + t - p.split] = VALUE(o);
    }
  }
}
