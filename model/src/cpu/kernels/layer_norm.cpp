#include "kernels/layer_norm.hpp"

#include <cmath>
#include <cstddef>

namespace neuflow::model {

void layer_norm_rows(RowsView in, RowsView out, RowsView residual, int rows, int dim, const std::vector<float>& gamma,
                     const std::vector<float>& beta) {
  constexpr double kEps = 1e-5;
#pragma omp parallel for
  for (int r = 0; r < rows; ++r) {
    const float* x = in.data + static_cast<std::size_t>(r) * in.ld;
    float* y = out.data + static_cast<std::size_t>(r) * out.ld;
    double mean = 0.0;
    for (int i = 0; i < dim; ++i) mean += x[i];
    mean /= dim;
    double var = 0.0;
    for (int i = 0; i < dim; ++i) var += (x[i] - mean) * (x[i] - mean);
    var /= dim;
    const double inv = 1.0 / std::sqrt(var + kEps);
    const float* res = residual.data ? residual.data + static_cast<std::size_t>(r) * residual.ld : nullptr;
    for (int i = 0; i < dim; ++i) {
      const float v = static_cast<float>((x[i] - mean) * inv) * gamma[static_cast<std::size_t>(i)] +
                      beta[static_cast<std::size_t>(i)];
      y[i] = res ? res[i] + v : v;
    }
  }
}

}  // namespace neuflow::model
