#pragma once
// NumPy .npy holding one float32 array of shape (H, W, 2) in C order: [..., 0] = u,
// [..., 1] = v. This is what `np.save("f.npy", flow.astype(np.float32))` writes for the usual
// H×W×2 layout.
//
// Reading accepts format versions 1.0, 2.0 and 3.0 with descr '<f4', fortran_order False and
// a 3-dimensional shape whose last axis is 2; anything else (float64, (2, H, W), Fortran
// order, big-endian) is rejected with a message saying what was found. NaN or infinite
// values make the pixel invalid (placeholder u = v = 0); the mask is left empty when every
// pixel is finite.
//
// Writing produces version 1.0 with the header padded to a multiple of 64 bytes, as numpy
// does. .npy has no mask, so invalid pixels are written as NaN, which reads back invalid.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

// Throws FlowFileError.
FlowField read_npy(const std::filesystem::path& path);

// Any little-endian float32, C-order array (what the reference tools dump as tensors).
struct NpyArray {
  std::vector<std::int64_t> shape;
  std::vector<float> data;  // product(shape) values, C order
};
// Called with the shape before any data is read or allocated; throws to refuse it.
using NpyShapeCheck = std::function<void(const std::vector<std::int64_t>& shape)>;
// Same header rules and errors as read_npy, without the (H, W, 2) requirement. The data size
// must match the file size exactly, so a header cannot make it allocate more than the file.
NpyArray read_npy_array(const std::filesystem::path& path, const NpyShapeCheck& check_shape = {});
// Atomic. Throws FlowFileError, or std::invalid_argument for an inconsistent field.
void write_npy(const FlowField& field, const std::filesystem::path& path);

}  // namespace neuflow::flow
