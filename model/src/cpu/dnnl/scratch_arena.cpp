#include "dnnl/scratch_arena.hpp"

#include <algorithm>
#include <stdexcept>

#include "dnnl/context.hpp"

namespace neuflow::model {

namespace {
constexpr std::size_t kAlignment = 64;  // a cache line; oneDNN's kernels prefer it
std::size_t align_up(std::size_t v) { return (v + kAlignment - 1) / kAlignment * kAlignment; }
}  // namespace

dnnl::memory ScratchArena::make(const dnnl::memory::desc& desc) {
  if (storage_) throw std::logic_error("ScratchArena: make() after finalize()");
  dnnl::memory m(desc, cpu_engine(), DNNL_MEMORY_NONE);
  bindings_.push_back({m, region_end_});
  region_end_ = align_up(region_end_ + desc.get_size());
  size_ = std::max(size_, region_end_);
  return m;
}

void ScratchArena::next_region() { region_end_ = 0; }

void ScratchArena::reserve_workspace(std::size_t bytes) {
  if (storage_) throw std::logic_error("ScratchArena: reserve_workspace() after finalize()");
  workspace_size_ = std::max(workspace_size_, align_up(bytes));
}

void ScratchArena::finalize() {
  storage_.reset(new std::byte[size_ + workspace_size_ + kAlignment]);
  auto* base = reinterpret_cast<std::byte*>(align_up(reinterpret_cast<std::size_t>(storage_.get())));
  for (auto& b : bindings_) b.memory.set_data_handle(base + b.offset);
  workspace_ = base + align_up(size_);
}

}  // namespace neuflow::model
