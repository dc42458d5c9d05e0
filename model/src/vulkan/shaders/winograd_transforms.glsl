// F(4×4, 3×3)'s transforms along one dimension (G, Bᵀ and Aᵀ), shared by the split shaders
// (winograd_input.comp, winograd_output.comp) and the fused one (winograd_conv.comp), which
// also transforms the filters (the split path's are transformed at upload, in double:
// winograd::F43::filter_1d, whose coefficients these are).

// G applied to three taps.
void filter_1d(float a, float b, float c, out float r[6]) {
  r[0] = a / 4.0;
  r[1] = -(a + b + c) / 6.0;
  r[2] = -(a - b + c) / 6.0;
  r[3] = a / 24.0 + b / 12.0 + c / 6.0;
  r[4] = a / 24.0 - b / 12.0 + c / 6.0;
  r[5] = c;
}

// Bᵀ applied to six values.
void input_1d(float d0, float d1, float d2, float d3, float d4, float d5, out float r[6]) {
  r[0] = 4.0 * d0 - 5.0 * d2 + d4;
  r[1] = d3 + d4 - 4.0 * (d1 + d2);
  r[2] = d4 - d3 + 4.0 * (d1 - d2);
  r[3] = d4 - d2 + 2.0 * (d3 - d1);
  r[4] = d4 - d2 + 2.0 * (d1 - d3);
  r[5] = 4.0 * d1 - 5.0 * d3 + d5;
}

// Aᵀ applied to six values.
void output_1d(float m0, float m1, float m2, float m3, float m4, float m5, out float o[4]) {
  const float sum12 = m1 + m2, diff12 = m1 - m2, sum34 = m3 + m4, diff34 = m3 - m4;
  o[0] = m0 + sum12 + sum34;
  o[1] = diff12 + 2.0 * diff34;
  o[2] = sum12 + 4.0 * sum34;
  o[3] = diff12 + 8.0 * diff34 + m5;
}
