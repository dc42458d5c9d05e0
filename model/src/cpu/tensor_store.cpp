#include "tensor_store.hpp"

#include <stdexcept>

#include "dnnl/context.hpp"

namespace neuflow::model {

namespace {
constexpr std::size_t kAlignment = 64;  // a cache line, and what AVX-512 loads want
}  // namespace

TensorStore::TensorStore(const graph::TensorTable& table) : table_(table), entries_(table.size()) {}

dnnl::memory::desc TensorStore::layout(graph::TensorId id) const {
  const Entry& e = entries_.at(index(id));
  if (e.blocked) {
    if (!e.layout) throw std::logic_error("the CPU's " + desc(id).name + " is read before its layout is chosen");
    return e.layout;
  }
  const graph::TensorDesc& d = desc(id);
  return nhwc_desc(d.h, d.w, d.c);
}

std::vector<std::size_t> TensorStore::bytes(const std::vector<Block>& blocks) const {
  std::vector<std::size_t> b(entries_.size(), 0);
  for (const Block& block : blocks) b.push_back(block.bytes);
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const Entry& e = entries_[i];
    const graph::TensorDesc& d = table_.descs()[i];
    if (d.storage != graph::Storage::transient || e.excluded) continue;
    b[i] = e.blocked ? e.layout.get_size() : d.count() * sizeof(float);
  }
  return b;
}

graph::LiveRanges TensorStore::with(graph::LiveRanges ranges, const std::vector<Block>& blocks) {
  for (const Block& block : blocks) ranges.push_back(block.ranges);
  return ranges;
}

std::vector<std::byte*> TensorStore::allocate(const graph::LiveRanges& ranges, const std::vector<Block>& blocks) {
  const std::vector<std::size_t> sizes = bytes(blocks);
  plan_ = graph::plan_offsets(sizes, with(ranges, blocks), kAlignment);
  storage_.reset(new std::byte[plan_.size + kAlignment]);
  const auto address = reinterpret_cast<std::uintptr_t>(storage_.get());
  auto* base = storage_.get() + ((kAlignment - address % kAlignment) % kAlignment);
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    const graph::TensorDesc& d = table_.descs()[i];
    if (d.storage == graph::Storage::persistent) {
      e.nhwc = Tensor(d.h, d.w, d.c);
      fill_constant_channels(d, e.nhwc);
    } else if (d.storage == graph::Storage::transient && sizes[i] > 0) {
      std::byte* at = base + plan_.offset[i];
      if (e.blocked) {
        e.memory = dnnl::memory(e.layout, cpu_engine(), at);
      } else {
        e.nhwc.h = d.h;
        e.nhwc.w = d.w;
        e.nhwc.c = d.c;
        e.nhwc.data.view(reinterpret_cast<float*>(at), d.count());
      }
    }
  }
  std::vector<std::byte*> addresses;
  for (std::size_t b = 0; b < blocks.size(); ++b) addresses.push_back(base + plan_.offset[entries_.size() + b]);
  return addresses;
}

void TensorStore::check(const graph::LiveRanges& ranges, const std::vector<Block>& blocks) const {
  graph::check_offsets(plan_, bytes(blocks), with(ranges, blocks), [&](std::size_t i) {
    return i < entries_.size() ? table_.descs()[i].name : blocks[i - entries_.size()].name;
  });
}

Tensor& TensorStore::nhwc(graph::TensorId id) {
  Entry& e = entry(id);
  const graph::TensorDesc& d = desc(id);
  if (e.blocked) throw std::logic_error("the CPU's " + d.name + " is in a convolution's layout, not NHWC");
  if (d.storage != graph::Storage::frame) {
    if (e.nhwc.data.empty()) throw std::logic_error("the CPU's " + d.name + " has no memory: no pass uses it");
    return e.nhwc;
  }
  FrameFeatures* frame = frames_[static_cast<std::size_t>(d.role)];
  if (!frame) throw std::logic_error("the network graph's " + d.name + " of a frame its pass does not bind");
  auto it = frame->tensors.find(d.name);
  if (it == frame->tensors.end()) {
    if (d.role != graph::FrameRole::encoded) {
      throw std::logic_error("a pair's frame without " + d.name + ": it was never encoded");
    }
    it = frame->tensors.emplace(d.name, Tensor(d.h, d.w, d.c)).first;
    fill_constant_channels(d, it->second);
  } else if (it->second.h != d.h || it->second.w != d.w || it->second.c != d.c) {
    if (d.role != graph::FrameRole::encoded) throw std::logic_error("a pair's frame encoded at another size");
    it->second.resize(d.h, d.w, d.c);
    fill_constant_channels(d, it->second);
  }
  return it->second;
}

dnnl::memory TensorStore::memory(graph::TensorId id) {
  if (entries_.at(index(id)).blocked) return entries_[index(id)].memory;
  return wrap_nhwc(nhwc(id));
}

void* TensorStore::data(graph::TensorId id) {
  if (entries_.at(index(id)).blocked) return entries_[index(id)].memory.get_data_handle();
  return nhwc(id).data.data();
}

void fill_constant_channels(const graph::TensorDesc& t, Tensor& out) {
  if (!t.constant) return;
  const std::vector<float> planar = graph::constant_values(t);
  const std::size_t plane = t.plane();
  for (int k = 0; k < t.constant->count; ++k) {
    for (std::size_t p = 0; p < plane; ++p) {
      out.data[p * static_cast<std::size_t>(t.c) + static_cast<std::size_t>(t.constant->first + k)] =
          planar[static_cast<std::size_t>(k) * plane + p];
    }
  }
}

}  // namespace neuflow::model
