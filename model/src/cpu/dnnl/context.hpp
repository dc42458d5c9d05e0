#pragma once
// The oneDNN engine is shared process-wide (it is thread-safe); each session owns a stream.
#include <dnnl.hpp>

#include "tensor.hpp"

namespace neuflow::model {

const dnnl::engine& cpu_engine();

// A plain NHWC float memory descriptor for a single image.
dnnl::memory::desc nhwc_desc(int h, int w, int c);

// Wraps a Tensor's storage as oneDNN memory (no copy; the tensor must outlive the memory).
dnnl::memory wrap_nhwc(Tensor& t);

}  // namespace neuflow::model
