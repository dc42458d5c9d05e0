#include "vulkan/vulkan_network.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "network_dims.hpp"
#include "vulkan/half_float.hpp"
#include "vulkan/inputs_in_parts.hpp"
#include "vulkan/network_recorder.hpp"
#include "vulkan/one_shot_commands.hpp"

namespace neuflow::model::vulkan {

VulkanNetwork::VulkanNetwork(std::shared_ptr<const DeviceWeights> weights, int height, int width,
                             ProductKernels products, ConvAlgorithm conv, GemmTiles gemm_tiles)
    : weights_(std::move(weights)),
      device_(*weights_->device),
      fp16_(weights_->fp16),
      products_(products),
      conv_(conv),
      gemm_tiles_(gemm_tiles),
      elem_(fp16_ ? 2 : 4),
      height_(height),
      width_(width),
      tokens_((height / 16) * (width / 16)) {
  if (products_ != ProductKernels::scalar && !fp16_) {
    throw std::logic_error("VulkanNetwork: the tensor-core products take fp16 tensors");
  }
  if (winograd_filters_at_upload(conv, products_) && weights_->winograd_filters.empty()) {
    throw std::logic_error("VulkanNetwork: these Winograd convolutions need the filters transformed at upload");
  }
  block_rows_ = std::clamp(kScoreBlockFloats / std::max(tokens_, 1), 1, tokens_);
  graph_ = graph::build_network_graph<DeviceTensor>(*weights_, height, width, graph::kPlanIterations, block_rows_);
  graph::check_shapes(graph_);
  // Tensors within three ops of each other never share a buffer: the graph puts independent ops
  // side by side (the two frames' steps, ConvBlocks in pairs and threes), which then run without a
  // barrier between them, as no write-after-read on a shared buffer orders them. Two ops apart
  // took 16 % more memory at full HD than packing tensors as tightly as their live ranges allow
  // and saved 4 barriers a streamed frame; three take 30 % more (73.1 M values, 65.8 M at two:
  // model_checkpoint_tests' MemoryPlan test prints both) and save one more, with the
  // convolutions that touch only their views (Recorder::touches_only), between the second
  // convolutions of block_8_1 and block_8_2, which write the two halves of one concatenation.
  constexpr int kApart = 3;
  plan_ = graph::plan_memory(graph_.tensors, planned_live_ranges(graph_.tensors, graph_.encode, graph_.flow, conv_),
                             kApart);
  allocate_tensors();

  // The buffers release themselves; the pool and fence are released here if setting up fails.
  try {
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = device_.queue_family();
    device_.check(vkCreateCommandPool(device_.handle(), &pool, nullptr, &pool_), "vkCreateCommandPool");
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    for (auto& t : ring_) device_.check(vkCreateFence(device_.handle(), &fence, nullptr, &t.fence), "vkCreateFence");
    if (device_.timestamp_bits() > 0) {
      VkQueryPoolCreateInfo queries{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
      queries.queryType = VK_QUERY_TYPE_TIMESTAMP;
      queries.queryCount = kTimestamps * kRing;
      device_.check(vkCreateQueryPool(device_.handle(), &queries, nullptr, &timestamps_), "vkCreateQueryPool");
    }
    initialise_constants();
  } catch (...) {
    release_handles();
    throw;
  }
}

VulkanNetwork::~VulkanNetwork() { release_handles(); }

void VulkanNetwork::release_handles() {
  VkDevice d = device_.handle();
  // Steps still running use the buffers and command buffers released below.
  for (const Started& s : started_) {
    vkWaitForFences(d, 1, &ring_[static_cast<std::size_t>(s.entry)].fence, VK_TRUE, UINT64_MAX);
  }
  started_.clear();
  if (timestamps_ != VK_NULL_HANDLE) vkDestroyQueryPool(d, timestamps_, nullptr);
  for (auto& t : ring_) {
    if (t.fence != VK_NULL_HANDLE) vkDestroyFence(d, t.fence, nullptr);
    t.fence = VK_NULL_HANDLE;
  }
  if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(d, pool_, nullptr);  // frees its command buffers
  for (VkDescriptorPool p : descriptor_pools_) vkDestroyDescriptorPool(d, p, nullptr);
  timestamps_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  descriptor_pools_.clear();
}

void VulkanNetwork::store(const float* values, std::size_t count, void* device_memory) const {
  if (fp16_) {
    auto* out = static_cast<std::uint16_t*>(device_memory);
    for (std::size_t i = 0; i < count; ++i) out[i] = to_half(values[i]);
  } else {
    std::memcpy(device_memory, values, count * sizeof(float));
  }
}

void VulkanNetwork::load(const void* device_memory, std::size_t count, float* values) const {
  if (fp16_) {
    const auto* in = static_cast<const std::uint16_t*>(device_memory);
    for (std::size_t i = 0; i < count; ++i) values[i] = from_half(in[i]);
  } else {
    std::memcpy(values, device_memory, count * sizeof(float));
  }
}

VkDescriptorSet VulkanNetwork::descriptor_set(const std::array<VkBuffer, kShaderBindings>& buffers) {
  if (auto it = descriptor_sets_.find(buffers); it != descriptor_sets_.end()) return it->second;
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorSetCount = 1;
  VkDescriptorSetLayout layout = device_.set_layout();
  alloc.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkResult r = VK_ERROR_OUT_OF_POOL_MEMORY;
  if (!descriptor_pools_.empty()) {
    alloc.descriptorPool = descriptor_pools_.back();
    r = vkAllocateDescriptorSets(device_.handle(), &alloc, &set);
  }
  if (r == VK_ERROR_OUT_OF_POOL_MEMORY || r == VK_ERROR_FRAGMENTED_POOL) {
    constexpr uint32_t kSets = 256;
    const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSets * VulkanDevice::kBindings};
    VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool.maxSets = kSets;
    pool.poolSizeCount = 1;
    pool.pPoolSizes = &size;
    VkDescriptorPool created = VK_NULL_HANDLE;
    device_.check(vkCreateDescriptorPool(device_.handle(), &pool, nullptr, &created), "vkCreateDescriptorPool");
    descriptor_pools_.push_back(created);
    alloc.descriptorPool = created;
    r = vkAllocateDescriptorSets(device_.handle(), &alloc, &set);
  }
  device_.check(r, "vkAllocateDescriptorSets");
  std::array<VkDescriptorBufferInfo, kShaderBindings> infos{};
  std::array<VkWriteDescriptorSet, kShaderBindings> writes{};
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    infos[i] = {buffers[i], 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set;
    writes[i].dstBinding = static_cast<uint32_t>(i);
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device_.handle(), static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  descriptor_sets_.emplace(buffers, set);
  return set;
}

namespace {
VkCommandBuffer allocate_commands(VulkanDevice& device, VkCommandPool pool) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  device.check(vkAllocateCommandBuffers(device.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  return cb;
}
}  // namespace

const VulkanNetwork::Pass& VulkanNetwork::cached(const std::string& key, int entry,
                                                 const std::function<void(Recorder&)>& record) {
  if (auto it = command_buffers_.find(key); it != command_buffers_.end()) return it->second;
  Pass pass{allocate_commands(device_, pool_), {}, entry};
  try {
    Recorder r(*this, pass.commands, nullptr, &pass.marks, entry);
    record(r);
    r.end();
    pass.work = r.work();
  } catch (...) {
    vkFreeCommandBuffers(device_.handle(), pool_, 1, &pass.commands);
    throw;
  }
  return command_buffers_.emplace(key, std::move(pass)).first->second;
}

void VulkanNetwork::run(const Pass& pass) {
  device_.submit_and_wait(pass.commands, ring_[static_cast<std::size_t>(pass.entry)].fence);
  work_ += pass.work;
  ++work_.submissions;
  ++work_.host_waits;
  read_stage_times(pass);
}

// Each stage's time is the difference to the timestamp before it, on a counter of
// timestamp_bits() bits that may wrap.
void VulkanNetwork::read_stage_times(const Pass& pass) {
  if (pass.marks.empty()) return;
  const auto count = static_cast<uint32_t>(pass.marks.size() + 1);
  timestamp_values_.resize(count);
  device_.check(vkGetQueryPoolResults(device_.handle(), timestamps_, static_cast<uint32_t>(pass.entry) * kTimestamps,
                                      count, count * sizeof(uint64_t), timestamp_values_.data(), sizeof(uint64_t),
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                "vkGetQueryPoolResults");
  const uint32_t bits = device_.timestamp_bits();
  const uint64_t mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  for (std::size_t i = 0; i < pass.marks.size(); ++i) {
    const uint64_t ticks = (timestamp_values_[i + 1] - timestamp_values_[i]) & mask;
    stage_times_.push_back({pass.marks[i], static_cast<double>(ticks) * device_.timestamp_period_ns() * 1e-6});
  }
}

void VulkanNetwork::require_idle(const char* call) const {
  if (!started_.empty()) {
    throw std::logic_error(std::string("VulkanNetwork::") + call + " while streamed steps are unfinished");
  }
}

void VulkanNetwork::fill_upload(const Transfer& t, const Frame* frame, const Tensor* image) {
  if (frame) {
    auto* dst = reinterpret_cast<std::uint8_t*>(t.upload.mapped());
    const std::size_t row = static_cast<std::size_t>(frame->layout.width) * 3;
    for (int y = 0; y < frame->layout.height; ++y) std::memcpy(dst + y * row, frame->data + y * frame->stride, row);
    return;
  }
  // Planar upload: the device layout is [C][H][W].
  const std::size_t hw = static_cast<std::size_t>(height_) * width_;
  staging_.resize(3 * hw);
  float* dst = staging_.data();
  for (std::size_t p = 0; p < hw; ++p) {
    dst[p] = image->data[3 * p];
    dst[hw + p] = image->data[3 * p + 1];
    dst[2 * hw + p] = image->data[3 * p + 2];
  }
  store(staging_.data(), staging_.size(), t.upload.mapped());
}

// The convex upsampling wrote it as the caller takes it.
void VulkanNetwork::read_flow(const Transfer& t, Tensor& out) {
  out.resize(height_, width_, 2);
  std::memcpy(out.data.data(), t.flow.mapped(), out.data.size() * sizeof(float));
}

// One recording per slot and layout: a session's frames keep one size and channel order.
std::string VulkanNetwork::encode_key(const FrameLayout* layout) {
  if (!layout) return "f32";
  return "u8:" + std::to_string(layout->width) + "x" + std::to_string(layout->height) + "+" +
         std::to_string(layout->pad_left) + "+" + std::to_string(layout->pad_top) + (layout->swap ? ":swap" : "");
}

void VulkanNetwork::encode(const Tensor& image, int slot) {
  require_idle("encode");
  fill_upload(ring_[0], nullptr, &image);
  run(cached("encode" + std::to_string(slot), 0, [&](Recorder& r) { record_encode(r, slot, nullptr); }));
}

void VulkanNetwork::encode(const Frame& frame, int slot) {
  require_idle("encode");
  fill_upload(ring_[0], &frame, nullptr);
  const std::string key = "encode" + std::to_string(slot) + ":" + encode_key(&frame.layout);
  run(cached(key, 0, [&](Recorder& r) { record_encode(r, slot, &frame.layout); }));
}

void VulkanNetwork::flow(int slot0, int slot1, const Iterations& iterations, Tensor& out,
                         const StageObserver* observer) {
  require_idle("flow");
  if (observer && *observer) {
    if (observed_commands_ == VK_NULL_HANDLE) observed_commands_ = allocate_commands(device_, pool_);
    Recorder r(*this, observed_commands_, observer);
    record_flow(r, slot0, slot1, iterations);
    r.run();
  } else {
    const std::string key = "flow" + std::to_string(slot0) + std::to_string(slot1) + ":" +
                            std::to_string(iterations.s16) + ":" + std::to_string(iterations.s8);
    run(cached(key, 0, [&](Recorder& r) { record_flow(r, slot0, slot1, iterations); }));
  }
  read_flow(ring_[0], out);
}

void VulkanNetwork::start(const Step& step) {
  if (started() >= kRing) throw std::logic_error("VulkanNetwork::start: every ring entry is in use");
  if ((step.frame == nullptr) == (step.image == nullptr)) {
    throw std::logic_error("VulkanNetwork::start: a step takes a frame or an image");
  }
  const int entry = next_entry_;
  const Transfer& t = ring_[static_cast<std::size_t>(entry)];
  const FrameLayout* layout = step.frame ? &step.frame->layout : nullptr;
  const bool pair = step.previous >= 0;
  std::string key = "step" + std::to_string(entry) + ":" + std::to_string(step.slot) + ":" + encode_key(layout);
  if (pair) {
    key += ":flow" + std::to_string(step.previous) + ":" + std::to_string(step.iterations.s16) + ":" +
           std::to_string(step.iterations.s8);
  }
  const Pass& pass = cached(key, entry, [&](Recorder& r) {
    record_encode(r, step.slot, layout);
    if (pair) record_flow(r, step.previous, step.slot, step.iterations);
  });
  fill_upload(t, step.frame, step.image);  // the entry's last step is finished: nothing reads it
  device_.submit(pass.commands, t.fence);
  work_ += pass.work;
  ++work_.submissions;
  started_.push_back({entry, &pass, pair});
  next_entry_ = (entry + 1) % kRing;
}

bool VulkanNetwork::finish(Tensor& out) {
  if (started_.empty()) throw std::logic_error("VulkanNetwork::finish: no step started");
  const Started s = started_.front();
  started_.pop_front();
  const Transfer& t = ring_[static_cast<std::size_t>(s.entry)];
  device_.wait(t.fence);
  ++work_.host_waits;
  read_stage_times(*s.pass);
  if (s.pair) read_flow(t, out);
  return s.pair;
}

}  // namespace neuflow::model::vulkan
