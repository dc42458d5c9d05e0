#pragma once
// One allocation for the transient activations of all stages of a plan. Stages run one after
// another, so buffers of different regions may share memory; buffers of the same region never
// overlap. Memories handed out before finalize() get their storage when it runs.
#include <dnnl.hpp>

#include <cstddef>
#include <memory>
#include <vector>

namespace neuflow::model {

class ScratchArena {
 public:
  // A memory in the current region (no storage until finalize()).
  dnnl::memory make(const dnnl::memory::desc& desc);

  // Buffers made after this may overlap those of earlier regions.
  void next_region();

  // Allocates the largest region's size once and binds every memory made so far.
  void finalize();

  // Room that one operation uses only while it runs (the Winograd convolutions' transformed
  // tiles): operations run one at a time, so all share one block of the largest size asked.
  void reserve_workspace(std::size_t bytes);
  std::byte* workspace() const { return workspace_; }  // after finalize()

  std::size_t size_bytes() const { return size_ + workspace_size_; }

 private:
  struct Binding {
    dnnl::memory memory;
    std::size_t offset;
  };
  std::vector<Binding> bindings_;
  std::size_t region_end_ = 0;
  std::size_t size_ = 0;
  std::size_t workspace_size_ = 0;
  std::byte* workspace_ = nullptr;
  std::unique_ptr<std::byte[]> storage_;
};

}  // namespace neuflow::model
