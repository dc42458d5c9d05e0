#pragma once
// The three transforms of a Winograd tile form T (F43, F63), each applied separably: the 1-D
// form over columns, then over rows.
#include "winograd/float8.hpp"

namespace neuflow::model::winograd {

// A kInputTile² tile of eight channels (row-major) to its points Bᵀ d B.
template <typename T>
void transform_input(const Float8* d, Float8* points) {
  constexpr int n = T::kInputTile;
  Float8 t[T::kPoints];
  for (int j = 0; j < n; ++j) T::input_1d(d + j, t + j, n);
  for (int i = 0; i < n; ++i) T::input_1d(t + n * i, points + n * i, 1);
}

// The points of products (eight channels) to the kOutputTile² output tile Aᵀ m A (row-major).
template <typename T>
void transform_output(const Float8* points, Float8* out) {
  constexpr int n = T::kInputTile, m = T::kOutputTile;
  Float8 t[m * n];  // m rows × n columns
  for (int j = 0; j < n; ++j) T::output_1d(points + j, t + j, n, n);
  for (int i = 0; i < m; ++i) T::output_1d(t + n * i, out + m * i, 1, 1);
}

// A 3×3 filter (row-major) to its points G g Gᵀ, computed in double.
template <typename T>
void transform_filter(const float* filter, float* points) {
  constexpr int n = T::kInputTile;
  double g[9], t[n * 3], p[T::kPoints];
  for (int i = 0; i < 9; ++i) g[i] = filter[i];
  for (int j = 0; j < 3; ++j) T::filter_1d(g + j, t + j, 3, 3);          // n rows × 3
  for (int i = 0; i < n; ++i) T::filter_1d(t + 3 * i, p + n * i, 1, 1);  // n × n
  for (int i = 0; i < T::kPoints; ++i) points[i] = static_cast<float>(p[i]);
}

}  // namespace neuflow::model::winograd
