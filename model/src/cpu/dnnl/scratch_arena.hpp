#pragma once
// One allocation for the transient activations of all stages of a plan. Stages run one after
// another, so buffers of different regions may share memory; buffers of the same region never
// overlap while both are in use. A stage whose operations run in the order it builds them
// may release() a buffer once it has built the last operation that reads it: buffers made
// afterwards may take its place. Memories handed out before finalize() get their storage
// when it runs, which is also when the offsets are chosen: knowing every buffer's lifetime,
// it places the largest first, each at the lowest offset free for its whole life (greedy by
// size), which leaves far less unused between buffers than placing them as they come.
#include <dnnl.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "tensor.hpp"

namespace neuflow::model {

class ScratchArena {
 public:
  // A memory in the current region (no storage until finalize()).
  dnnl::memory make(const dnnl::memory::desc& desc);

  // A stage's own NHWC tensor in the current region: `tensor` takes the shape h×w×c now and
  // becomes a view of its buffer when finalize() runs, so it must not move before then. What
  // it holds lasts only while its stage runs (later stages' buffers share the memory).
  void make_tensor(Tensor& tensor, int h, int w, int c);

  // `memory` (made in the current region) is read by nothing built after this point.
  void release(const dnnl::memory& memory);
  void release(const Tensor& tensor);

  // Buffers made after this may overlap those of earlier regions. `name` says whose they are.
  void next_region(std::string name = {});
  // Names the current region (the first one has no next_region call).
  void name_region(std::string name);

  // What each region holds, for the memory table of a plan (bytes: once finalized).
  struct Region {
    std::string name;
    std::size_t bytes = 0;
    int buffers = 0;
  };
  const std::vector<Region>& regions() const { return regions_; }

  // Allocates the largest region's size once and binds every memory made so far.
  void finalize();
  // Or in two steps, into memory of the caller's: the bytes it needs (offsets chosen), then
  // every memory bound at `base` (aligned to 64 bytes, plan() bytes long, kept by the caller).
  std::size_t plan();
  void bind(std::byte* base);

  std::size_t size_bytes() const { return size_; }

 private:
  struct Binding {
    dnnl::memory memory;
    std::size_t size;
    std::size_t region;
    std::size_t made;  // lifetime [made, released) in make/release events
    std::size_t released = kForever;
    std::size_t offset = 0;    // chosen by finalize()
    Tensor* tensor = nullptr;  // bound to the memory by finalize()
  };
  static constexpr std::size_t kForever = static_cast<std::size_t>(-1);
  void place_region(std::size_t region);

  std::vector<Binding> bindings_;
  std::vector<Region> regions_{1};
  std::size_t events_ = 0;
  std::size_t size_ = 0;
  bool planned_ = false;
  std::unique_ptr<std::byte[]> storage_;
};

}  // namespace neuflow::model
