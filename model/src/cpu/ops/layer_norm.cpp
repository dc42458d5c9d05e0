#include "ops/layer_norm.hpp"

#include <cmath>

namespace neuflow::model {

void layer_norm_rows(float* data, int rows, int dim, const std::vector<float>& gamma, const std::vector<float>& beta) {
  constexpr double kEps = 1e-5;
#pragma omp parallel for
  for (int r = 0; r < rows; ++r) {
    float* x = data + static_cast<std::size_t>(r) * dim;
    double mean = 0.0;
    for (int i = 0; i < dim; ++i) mean += x[i];
    mean /= dim;
    double var = 0.0;
    for (int i = 0; i < dim; ++i) var += (x[i] - mean) * (x[i] - mean);
    var /= dim;
    const double inv = 1.0 / std::sqrt(var + kEps);
    for (int i = 0; i < dim; ++i) {
      x[i] = static_cast<float>((x[i] - mean) * inv) * gamma[i] + beta[i];
    }
  }
}

}  // namespace neuflow::model
