#pragma once

namespace neuflow::model::winograd {

// A form's tile sizes: F(m×m, 3×3) reads the (m + 2)² input tile around its m² outputs and
// multiplies at as many points.
template <int OutputTile>
struct TileSizes {
  static constexpr int kOutputTile = OutputTile;
  static constexpr int kInputTile = OutputTile + 2;
  static constexpr int kPoints = kInputTile * kInputTile;
};

}  // namespace neuflow::model::winograd
