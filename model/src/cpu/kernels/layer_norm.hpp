#pragma once
#include <vector>

namespace neuflow::model {

// Rows `ld` floats apart (a channel range of NHWC tokens); data == nullptr: none.
struct RowsView {
  float* data = nullptr;
  int ld = 0;
};

// Over `rows` rows of `dim` values: out = (in - mean) / sqrt(var + 1e-5) * gamma + beta
// (+ residual). `out` may be `in`.
void layer_norm_rows(RowsView in, RowsView out, RowsView residual, int rows, int dim, const std::vector<float>& gamma,
                     const std::vector<float>& beta);

}  // namespace neuflow::model
