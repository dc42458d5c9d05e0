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
  if (planned_) throw std::logic_error("ScratchArena: make() after finalize()");
  dnnl::memory m(desc, cpu_engine(), DNNL_MEMORY_NONE);
  bindings_.push_back({m, align_up(desc.get_size()), regions_.size() - 1, events_++});
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
  const auto b =
      std::find_if(bindings_.begin(), bindings_.end(), [&](const Binding& x) { return x.tensor == &tensor; });
  if (b == bindings_.end()) throw std::logic_error("ScratchArena: release() of a tensor it did not make");
  release(b->memory);
}

void ScratchArena::release(const dnnl::memory& memory) {
  const auto b = std::find_if(bindings_.begin(), bindings_.end(),
                              [&](const Binding& x) { return x.memory.get() == memory.get(); });
  if (b == bindings_.end()) throw std::logic_error("ScratchArena: release() of a memory it did not make");
  if (b->region != regions_.size() - 1 || b->released != kForever) {
    throw std::logic_error("ScratchArena: release() of a memory of an earlier region, or twice");
  }
  b->released = events_++;
}

void ScratchArena::next_region(std::string name) { regions_.push_back({std::move(name), 0, 0}); }

void ScratchArena::name_region(std::string name) { regions_.back().name = std::move(name); }

void ScratchArena::place_region(std::size_t region) {
  std::vector<Binding*> order;
  for (auto& b : bindings_) {
    if (b.region == region) order.push_back(&b);
  }
  std::stable_sort(order.begin(), order.end(), [](const Binding* a, const Binding* b) { return a->size > b->size; });
  std::vector<const Binding*> placed;
  std::size_t end = 0;
  for (Binding* b : order) {
    // The placed buffers alive at some moment of b's life, by offset; b takes the first gap.
    std::vector<const Binding*> clashes;
    for (const Binding* p : placed) {
      if (p->made < b->released && b->made < p->released) clashes.push_back(p);
    }
    std::sort(clashes.begin(), clashes.end(), [](const Binding* x, const Binding* y) { return x->offset < y->offset; });
    std::size_t offset = 0;
    for (const Binding* c : clashes) {
      if (c->offset >= offset + b->size) break;
      offset = std::max(offset, c->offset + c->size);
    }
    b->offset = offset;
    end = std::max(end, offset + b->size);
    placed.push_back(b);
  }
  regions_[region].bytes = end;
  size_ = std::max(size_, end);
}

void ScratchArena::finalize() {
  const std::size_t bytes = plan();
  storage_.reset(new std::byte[bytes + kAlignment]);
  bind(reinterpret_cast<std::byte*>(align_up(reinterpret_cast<std::size_t>(storage_.get()))));
}

std::size_t ScratchArena::plan() {
  if (!planned_) {
    for (std::size_t r = 0; r < regions_.size(); ++r) place_region(r);
    planned_ = true;
  }
  return size_;
}

void ScratchArena::bind(std::byte* base) {
  plan();
  for (auto& b : bindings_) {
    b.memory.set_data_handle(base + b.offset);
    if (b.tensor)
      b.tensor->data.view(static_cast<float*>(static_cast<void*>(base + b.offset)), b.tensor->pixels() * b.tensor->c);
  }
}

}  // namespace neuflow::model
