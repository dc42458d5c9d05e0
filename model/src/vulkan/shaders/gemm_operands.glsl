// What the three kinds of product read and where they write, shared by the scalar tiles
// (matmul.comp) and the fragment tiles of the tensor-core path (matmul_fragments.comp), so the
// two cannot disagree on an operand:
//  - IMPLICIT_CONV: A is a convolution's OIHW weights read as a row-major [Cout][Cin·k·k]
//    matrix and B the im2col of a planar [C][H][W] input, gathered on the fly (never stored);
//    C is the planar output. Bias and activation fused; `addend` (same shape as C) is added
//    before the activation.
//  - WINOGRAD_GEMM: the 36 products of F(4×4, 3×3), one per workgroup z: the transformed
//    filters [36][Cout][Cin] (binding 0, both sides padded to 16) by the transformed input tiles [36][Cin][tiles] into
//    [36][Cout][tiles]; the tiles and products are fp32 in either precision.
//  - otherwise a general strided product (attention, matching): every operand has a row and a
//    column stride, so transposes are free.
// Needs the bindings (a_data, b_data, c_data, d_data) and the push constants p declared.

#include "activate.glsl"

#ifdef MLP
// The MLP's two products in one dispatch (matmul_norm_params.h): in phase 0 its hidden layer
// act(W1 · x + b1) for the workgroup's columns, a block of rows at a time, into workgroup memory
// (rounded to the stored type, as the first product would have stored it); in phase 1
// W2 · hidden, which the LayerNorm epilogue takes. The hidden layer's memory then holds the
// second product's values for the LayerNorm (layer_norm_tile.glsl).
shared VALUE mlp_hidden[kMlpHiddenChannels * 16];  // [hidden channel][column of the tile, of 16]
int mlp_phase = 0;
int mlp_col0() { return int(gl_WorkGroupID.x) * 16; }
#endif

#ifdef IMPLICIT_CONV
int gemm_m() { return p.out_c; }
int gemm_n() { return p.out_h * p.out_w; }
int gemm_k() { return p.in_c * p.kernel * p.kernel; }
#elif defined(MLP)
int gemm_m() { return mlp_phase == 0 ? p.hidden : p.m; }
int gemm_n() { return p.n; }
int gemm_k() { return mlp_phase == 0 ? p.k : p.hidden; }
#else
int gemm_m() { return p.m; }
int gemm_n() { return p.n; }
int gemm_k() { return p.k; }
#endif

// A column of B as one invocation gathers it through the whole K loop: where a convolution's
// window starts is worked out once, not per element.
struct GemmColumn {
  int n;
  bool ok;
  int iy0, ix0;
};

GemmColumn gemm_column(int n) {
  GemmColumn c;
  c.n = n;
  c.ok = n < gemm_n();
#ifdef IMPLICIT_CONV
  const int oy = n / p.out_w, ox = n - (n / p.out_w) * p.out_w;
  c.iy0 = oy * p.stride - p.pad;
  c.ix0 = ox * p.stride - p.pad;
#else
  c.iy0 = 0;
  c.ix0 = 0;
#endif
  return c;
}

// A[m][k], 0 outside the matrix.
float gemm_a(int m, int k) {
  if (m >= gemm_m() || k >= gemm_k()) return 0.0;
#if defined(IMPLICIT_CONV)
  return float(a_data[p.w_off + m * gemm_k() + k]);
#elif defined(WINOGRAD_GEMM)
  return float(a_data[p.w_off + (int(gl_WorkGroupID.z) * p.filters_out + m) * p.filters_in + k]);
#elif defined(MLP)
  return float(a_data[(mlp_phase == 0 ? p.a_off : p.w2_off) + m * gemm_k() + k]);
#else
  return float(a_data[p.a_off + m * p.a_rs + k * p.a_cs]);
#endif
}

// Where an invocation is along K as it gathers B: for a convolution, k's input channel and tap
// (k = (ci · kernel + ky) · kernel + kx), kept by additions as k moves, so that no gathered
// element pays the two integer divisions that finding them from k takes (tens of instructions
// each on a GPU, and scalar ones on a CPU's vector units).
struct GemmCursor {
  int k;
  int ci, ky, kx;
};

GemmCursor gemm_cursor(int k) {
  GemmCursor c;
  c.k = k;
#ifdef IMPLICIT_CONV
  const int taps = p.kernel * p.kernel;
  c.ci = k / taps;
  const int rem = k - c.ci * taps;
  c.ky = rem / p.kernel;
  c.kx = rem - c.ky * p.kernel;
#else
  c.ci = 0;
  c.ky = 0;
  c.kx = 0;
#endif
  return c;
}

// The cursor `step` further along K, `step` decomposed once by gemm_cursor(step).
void gemm_advance(inout GemmCursor c, GemmCursor step) {
  c.k += step.k;
#ifdef IMPLICIT_CONV
  c.kx += step.kx;
  if (c.kx >= p.kernel) {
    c.kx -= p.kernel;
    ++c.ky;
  }
  c.ky += step.ky;
  if (c.ky >= p.kernel) {
    c.ky -= p.kernel;
    ++c.ci;
  }
  c.ci += step.ci;
#endif
}

// B[k][column] at the cursor's k, 0 outside the matrix (and in a convolution's padding).
float gemm_b(GemmColumn col, GemmCursor c) {
  if (!col.ok || c.k >= gemm_k()) return 0.0;
#if defined(IMPLICIT_CONV)
  const int iy = col.iy0 + c.ky, ix = col.ix0 + c.kx;
  if (iy < 0 || iy >= p.in_h || ix < 0 || ix >= p.in_w) return 0.0;
  return float(b_data[p.in_off + (c.ci * p.in_h + iy) * p.in_w + ix]);
#elif defined(WINOGRAD_GEMM)
  return b_data[(int(gl_WorkGroupID.z) * gemm_k() + c.k) * gemm_n() + col.n];
#elif defined(MLP)
  if (mlp_phase == 1) return float(mlp_hidden[c.k * 16 + col.n - mlp_col0()]);
  return float(b_data[p.b_off + c.k * p.b_rs + col.n * p.b_cs]);
#else
  return float(b_data[p.b_off + c.k * p.b_rs + col.n * p.b_cs]);
#endif
}

#ifdef CONVEX_UPSAMPLE
#define PRODUCT_STORE convex_store  // convex_upsample_tile.glsl
#elif defined(MLP)
#define PRODUCT_STORE mlp_store  // the hidden layer's, then norm_stage (layer_norm_tile.glsl)
#elif defined(LAYER_NORM)
#define PRODUCT_STORE norm_stage  // layer_norm_tile.glsl
#else
#define PRODUCT_STORE gemm_store

// Writes C[m][n] from its sum of products, with what the product fuses (scale, bias, addend,
// activation); nothing outside the matrix.
void gemm_store(int m, int n, float sum) {
  if (m >= gemm_m() || n >= gemm_n()) return;
#if defined(IMPLICIT_CONV)
  float v = p.alpha * sum;
  if (p.bias_off >= 0) v += float(a_data[p.bias_off + m]);
  if (p.add_off >= 0) v += float(d_data[p.add_off + m * gemm_n() + n]);
  c_data[p.out_off + m * gemm_n() + n] = VALUE(activate(v, p.act));
#elif defined(WINOGRAD_GEMM)
  c_data[(int(gl_WorkGroupID.z) * gemm_m() + m) * gemm_n() + n] = sum;
#else
  float v = p.alpha * sum;
  if (p.bias_off >= 0) v += float(a_data[p.bias_off + m]);
  c_data[p.c_off + m * p.c_rs + n * p.c_cs] = VALUE(activate(v, p.act));
#endif
}
#endif
