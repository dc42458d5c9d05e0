#pragma once
#include <vector>

namespace neuflow::model {

// In place over `rows` contiguous rows of `dim` values: (x - mean) / sqrt(var + 1e-5) * gamma + beta.
void layer_norm_rows(float* data, int rows, int dim, const std::vector<float>& gamma, const std::vector<float>& beta);

}  // namespace neuflow::model
