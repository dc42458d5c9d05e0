// F(4×4, 3×3)'s tiles read from and written to the planar tensors, shared by the split shaders
// and the fused one. The including shader defines which it uses and declares what they touch:
// READS_INPUT_TILES for input_tile, which reads `src` (p.h × p.w planes at p.in_off; with
// INPUT_IN_PARTS, `src` and `src2` as winograd_conv_params.h describes); WRITES_OUTPUT_TILES
// for store_output_tile, which writes `dst` and reads `addend` (p.out_off, p.add_off, p.act).
#include "winograd_transforms.glsl"

#ifdef READS_INPUT_TILES
// d[r][c] = BUF at row (y0 + r) >> SHIFT, column (x0 + c) >> SHIFT of the plane at BASE, W
// values a row (the input, or a part of it stored at 1 / 2^SHIFT of its size); zeros outside the
// input (padding 1), and everywhere where !inside.
#define LOAD_INPUT_TILE(BUF, BASE, SHIFT, W)                                                                  \
  for (int r = 0; r < 6; ++r) {                                                                               \
    const int y = y0 + r;                                                                                     \
    for (int c = 0; c < 6; ++c) {                                                                             \
      const int x = x0 + c;                                                                                   \
      d[r][c] = (inside && y >= 0 && y < p.h && x >= 0 && x < p.w) ? float(BUF[(BASE) + (y >> (SHIFT)) * (W) + \
                                                                               (x >> (SHIFT))])               \
                                                                     : 0.0;                                  \
    }                                                                                                         \
  }

// Bᵀ d B of the 6×6 input tile d of channel ci around 4×4 output tile (ty, tx) (p.h × p.w
// planes): zeros outside the input (padding 1), and everywhere where !inside. Point 6 i + j in
// v[6 i + j]. With INPUT_IN_PARTS, channel ci where the concatenation's parts lie
// (winograd_conv_params.h): `src` or the including shader's `src2`, upsampled by 2^shift, through
// ReLU, scaled and rounded to the stored type, as the resamples that would have written the
// concatenated input store it; the part and its plane are worked out once a tile.
void input_tile(int ci, int ty, int tx, bool inside, out float v[36]) {
  const int y0 = 4 * ty - 1, x0 = 4 * tx - 1;
  float d[6][6];
#ifdef INPUT_IN_PARTS
  const bool second = ci >= p.part_c;
  const int shift = second ? p.shift2 : p.shift;
  const int w = p.w >> shift, plane = (p.h >> shift) * w;
  if (second) {
    LOAD_INPUT_TILE(src2, p.in2_off + (ci - p.part_c) * plane, shift, w)
  } else {
    LOAD_INPUT_TILE(src, p.in_off + ci * plane, shift, w)
  }
  const bool relu = (p.relu_parts & (second ? 2 : 1)) != 0;
  const float scale = second ? p.scale2 : p.scale;
  if (relu || scale != 1.0) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) d[r][c] = float(VALUE((relu ? max(d[r][c], 0.0) : d[r][c]) * scale));
    }
  }
#else
  LOAD_INPUT_TILE(src, p.in_off + ci * p.h * p.w, 0, p.w)
#endif
  float cols[6][6];  // Bᵀ d: each column transformed
  for (int c = 0; c < 6; ++c) {
    float r[6];
    input_1d(d[0][c], d[1][c], d[2][c], d[3][c], d[4][c], d[5][c], r);
    for (int i = 0; i < 6; ++i) cols[i][c] = r[i];
  }
  for (int i = 0; i < 6; ++i) {  // (Bᵀ d) B: each row
    float r[6];
    input_1d(cols[i][0], cols[i][1], cols[i][2], cols[i][3], cols[i][4], cols[i][5], r);
    for (int j = 0; j < 6; ++j) v[6 * i + j] = r[j];
  }
}
#endif

#ifdef WRITES_OUTPUT_TILES
// Aᵀ (m A) of output channel `co`, tile (ty, tx), from its products' rows already times A,
// then bias, addend and activation, as the direct convolution applies them.
void store_output_tile(int co, int ty, int tx, float rows[6][4], float bias) {
  const int plane = p.h * p.w;
  for (int j = 0; j < 4; ++j) {  // each column
    float o[4];
    output_1d(rows[0][j], rows[1][j], rows[2][j], rows[3][j], rows[4][j], rows[5][j], o);
    const int x = 4 * tx + j;
    if (x >= p.w) continue;
    for (int r = 0; r < 4; ++r) {
      const int y = 4 * ty + r;
      if (y >= p.h) continue;
      const int at = co * plane + y * p.w + x;
      float v = o[r] + bias;
      if (p.add_off >= 0) v += float(addend[p.add_off + at]);
      dst[p.out_off + at] = VALUE(activate(v, p.act));
    }
  }
}
#endif
