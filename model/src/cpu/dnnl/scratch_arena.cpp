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
  const std::size_t size = align_up(desc.get_size());
  // The first released span it fits in, else the region's end.
  std::size_t offset = region_end_;
  const auto fit = std::find_if(free_.begin(), free_.end(), [&](const Span& f) { return f.size >= size; });
  if (fit != free_.end()) {
    offset = fit->offset;
    fit->offset += size;
    fit->size -= size;
    if (fit->size == 0) free_.erase(fit);
  } else {
    region_end_ += size;
  }
  bindings_.push_back({m, offset, size, regions_.size() - 1});
  size_ = std::max(size_, region_end_);
  regions_.back().bytes = std::max(regions_.back().bytes, region_end_);
  ++regions_.back().buffers;
  return m;
}

void ScratchArena::make_tensor(Tensor& tensor, int h, int w, int c) {
  tensor.h = h;
  tensor.w = w;
  tensor.c = c;
  tensor.data = TensorData();
  make(nhwc_desc(h, w, c));
  bindings_.back().tensor = &tensor;
}

void ScratchArena::release(const Tensor& tensor) {
  const auto b = std::find_if(bindings_.begin(), bindings_.end(), [&](const Binding& x) { return x.tensor == &tensor; });
  if (b == bindings_.end()) throw std::logic_error("ScratchArena: release() of a tensor it did not make");
  release(b->memory);
}

void ScratchArena::release(const dnnl::memory& memory) {
  const auto b = std::find_if(bindings_.begin(), bindings_.end(),
                              [&](const Binding& x) { return x.memory.get() == memory.get(); });
  if (b == bindings_.end()) throw std::logic_error("ScratchArena: release() of a memory it did not make");
  if (b->region != regions_.size() - 1 || b->released) {
    throw std::logic_error("ScratchArena: release() of a memory of an earlier region, or twice");
  }
  b->released = true;
  Span span{b->offset, b->size};
  // Merged with its free neighbours, so larger buffers fit later.
  auto at = std::lower_bound(free_.begin(), free_.end(), span.offset,
                             [](const Span& f, std::size_t offset) { return f.offset < offset; });
  at = free_.insert(at, span);
  if (at + 1 != free_.end() && at->offset + at->size == (at + 1)->offset) {
    at->size += (at + 1)->size;
    free_.erase(at + 1);
  }
  if (at != free_.begin() && (at - 1)->offset + (at - 1)->size == at->offset) {
    (at - 1)->size += at->size;
    free_.erase(at);
  }
}

void ScratchArena::next_region(std::string name) {
  region_end_ = 0;
  free_.clear();
  regions_.push_back({std::move(name), 0, 0});
}

void ScratchArena::name_region(std::string name) { regions_.back().name = std::move(name); }

void ScratchArena::reserve_workspace(std::size_t bytes) {
  if (storage_) throw std::logic_error("ScratchArena: reserve_workspace() after finalize()");
  workspace_size_ = std::max(workspace_size_, align_up(bytes));
}

void ScratchArena::finalize() {
  storage_.reset(new std::byte[size_ + workspace_size_ + kAlignment]);
  auto* base = reinterpret_cast<std::byte*>(align_up(reinterpret_cast<std::size_t>(storage_.get())));
  for (auto& b : bindings_) {
    b.memory.set_data_handle(base + b.offset);
    if (b.tensor) b.tensor->data.view(static_cast<float*>(static_cast<void*>(base + b.offset)), b.tensor->pixels() * b.tensor->c);
  }
  workspace_ = base + align_up(size_);
}

}  // namespace neuflow::model
