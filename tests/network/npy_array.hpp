#pragma once
// Reads the fixture's float32 .npy tensors (any rank, C order) for comparisons in tests.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace neuflow::test {

struct NpyArray {
  std::vector<int64_t> shape;
  std::vector<float> data;
};

// Throws std::runtime_error naming the file if it is not a little-endian float32 C-order array.
NpyArray read_npy_array(const std::filesystem::path& path);

}  // namespace neuflow::test
