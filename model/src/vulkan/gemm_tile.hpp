#pragma once
// The tile a product (the implicit-GEMM convolutions, the split Winograd products, the matrix
// products) runs in: on the scalar kernel (matmul.comp) 16×16 invocations of TM×TN outputs; on
// tensor cores or their twin (matmul_fragments.comp) subgroups of 16×16 fragments. Fixed by
// specialization constants, so that each size is its own pipeline with its loops unrolled.
// Larger tiles read each operand fewer times (an invocation's 8×8 outputs take 16 loads from
// workgroup memory for 64 multiply-adds, 4×4 take 8 for 16), but a grid of few tiles leaves most
// of a large GPU's compute units without work: a layer takes the largest tile whose grid still
// has the device's wide grid of workgroups, else the smallest. NEUFLOW_VULKAN_GEMM_TILE=
// auto|32|64|128 chooses (auto, the default: by the grid as above; a number: that tile for every
// product, to compare).
#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace neuflow::model::vulkan {

struct GemmTile {
  int tm = 4, tn = 4;  // outputs per invocation along M (rows of C) and N (its columns)
  constexpr int rows() const { return 16 * tm; }
  constexpr int columns() const { return 16 * tn; }
  // matmul_fragments.comp's workgroup: subgroups of 32, 2 across the tile's columns and 4 down
  // its rows for 128×128 (2×4 fragments each), else 2 (2×2 fragments each at 64×64, one at 32×32);
  // matmul_norm's 192×16: 4 subgroups down its rows (3 fragments each).
  int fragment_invocations() const { return rows() >= 128 && columns() >= 128 ? 256 : 128; }
  bool operator==(const GemmTile&) const = default;
};

inline constexpr GemmTile kGemmTile32{2, 2}, kGemmTile64{4, 4}, kGemmTile128{8, 8};

// How a device's products (scalar and on fragments alike) choose their tiles.
struct GemmTiles {
  int forced = 0;      // 32, 64 or 128: that tile everywhere; 0: by the grid
  long wide_grid = 1;  // the fewest workgroups that keep the device busy
};

// A GPU: two workgroups for each of the 132 compute units of an H100 would be 264; 128 keeps a
// GPU of half that size (an RTX 4070's 46 SMs, a Radeon's 60 CUs) at two or more, and a Jetson
// Orin (8 or 16 SMs) takes the largest tile that many workgroups allow. A CPU device (lavapipe)
// runs a workgroup per core: there 128×128 tiles take 0.85× the time of 64×64 ones a frame at
// 160×128 with every convolution direct, and 32×32 ones 1.6× (docs/benchmarks.md).
inline constexpr long kGpuWideGrid = 128;

// From NEUFLOW_VULKAN_GEMM_TILE (std::invalid_argument naming it for anything else) and the
// device: `gpu` (GpuDevice::is_gpu()), else `cpu_threads` workgroups at once.
inline GemmTiles gemm_tiles_for(bool gpu, unsigned cpu_threads) {
  GemmTiles tiles{0, gpu ? kGpuWideGrid : std::max<long>(cpu_threads, 1)};
  const char* v = std::getenv("NEUFLOW_VULKAN_GEMM_TILE");
  const std::string want = v == nullptr ? "" : v;
  if (want == "32" || want == "64" || want == "128") {
    tiles.forced = std::stoi(want);
  } else if (!want.empty() && want != "auto") {
    throw std::invalid_argument("NEUFLOW_VULKAN_GEMM_TILE: expected auto, 32, 64 or 128, got \"" + want + "\"");
  }
  return tiles;
}

// The tile for an M×N product repeated `batches` times (the split Winograd's 36).
inline GemmTile gemm_tile_for(long m, long n, long batches, const GemmTiles& tiles) {
  if (tiles.forced == 32) return kGemmTile32;
  if (tiles.forced == 64) return kGemmTile64;
  if (tiles.forced == 128) return kGemmTile128;
  const auto grid = [&](const GemmTile& t) {
    return ((m + t.rows() - 1) / t.rows()) * ((n + t.columns() - 1) / t.columns()) * batches;
  };
  for (const GemmTile& t : {kGemmTile128, kGemmTile64}) {
    if (grid(t) >= tiles.wide_grid) return t;
  }
  return kGemmTile32;
}

}  // namespace neuflow::model::vulkan
