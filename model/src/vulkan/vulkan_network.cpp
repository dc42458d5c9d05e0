#include "vulkan/vulkan_network.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "network_dims.hpp"
#include "vulkan/half_float.hpp"
#include "vulkan/one_shot_commands.hpp"

namespace neuflow::model::vulkan {

namespace {

constexpr int kDim = kFeatureChannels;  // attention tokens' width
// The attention's and matching's score blocks hold at most this many floats (32 MiB), well
// inside lavapipe's 128 MiB per buffer, so memory stays O(L · block) at any size.
constexpr int kScoreBlockFloats = 8 << 20;
constexpr int kLocal = 256;  // invocations per workgroup of the element-wise shaders

// An activation code of shaders/params/activation.h.
using Act = int;

// Element-wise shaders loop over what a capped dispatch does not cover (common.glsl).
uint32_t groups(long count, long per_group) {
  return static_cast<uint32_t>(std::clamp<long>((count + per_group - 1) / per_group, 1, 65535));
}

// The tiled products do not loop: each workgroup is one 64×64 tile, so the grid must fit.
uint32_t tiles(long count, const char* what) {
  const long n = (count + 63) / 64;
  if (n > 65535) {
    throw BackendError(BackendError::Kind::unavailable, std::string("a model size too large for one dispatch of ") +
                                                            what + ": choose a smaller model-width/model-height");
  }
  return static_cast<uint32_t>(std::max<long>(n, 1));
}

}  // namespace

// Records one pass: every command is preceded by a barrier that orders it after everything
// before it (the network is a chain; there is little to overlap inside one pass). With an
// observer, observe() ends the command buffer, runs it, reads the tensor back and goes on in
// a fresh recording.
class VulkanNetwork::Recorder {
 public:
  // marks: where the stages' timestamps go (nullptr: not timed, as with an observer).
  // entry: the ring entry whose upload, read-back and timestamps the pass uses.
  Recorder(VulkanNetwork& net, VkCommandBuffer commands, const StageObserver* observer,
           std::vector<std::string>* marks = nullptr, int entry = 0)
      : net_(net),
        commands_(commands),
        observer_(observer && *observer ? observer : nullptr),
        marks_(observer_ || net.timestamps_ == VK_NULL_HANDLE ? nullptr : marks),
        transfer_(net.ring_[static_cast<std::size_t>(entry)]),
        query_base_(static_cast<uint32_t>(entry) * kTimestamps) {
    begin();
    if (marks_) {
      vkCmdResetQueryPool(commands_, net_.timestamps_, query_base_, kTimestamps);
      vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, net_.timestamps_, query_base_);
    }
  }

  const Buffer& upload() const { return transfer_.upload; }
  const Buffer& readback() const { return transfer_.readback; }

  // The end of the stage `name`: a timestamp once everything recorded before it has run.
  // Consecutive names without work between them (the backbone's outputs that the flow pass
  // only reads) take no timestamp.
  void mark(const std::string& name) {
    if (!marks_ || !worked_ || marks_->size() + 1 >= kTimestamps) return;
    marks_->push_back(name);
    vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, net_.timestamps_,
                        query_base_ + static_cast<uint32_t>(marks_->size()));
    worked_ = false;
  }

  void begin() {
    net_.device_.check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    net_.device_.check(vkBeginCommandBuffer(commands_, &info), "vkBeginCommandBuffer");
  }
  void end() { net_.device_.check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer"); }
  void run() {
    end();
    net_.device_.submit_and_wait(commands_, transfer_.fence);
  }

  // Makes a copy into a host-visible buffer visible to the host once the fence has signalled.
  void host_barrier() {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &b, 0, nullptr, 0,
                         nullptr);
  }

  void barrier() {
    worked_ = true;  // every command is recorded after its barrier
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                      VK_ACCESS_TRANSFER_WRITE_BIT;
    const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vkCmdPipelineBarrier(commands_, stages, stages, 0, 1, &b, 0, nullptr, 0, nullptr);
  }

  // S's push constants are its params header's struct (ShaderParams), so recording a shader with
  // another's parameters does not compile.
  template <Shader S>
  void dispatch(std::array<const Buffer*, 4> bindings, const typename ShaderParams<S>::type& push, uint32_t gx,
                uint32_t gy = 1) {
    record_dispatch(S, bindings, &push, sizeof push, gx, gy);
  }

  void record_dispatch(Shader shader, std::array<const Buffer*, 4> bindings, const void* push, std::size_t bytes,
                       uint32_t gx, uint32_t gy) {
    barrier();
    std::array<VkBuffer, 4> handles{};
    for (std::size_t i = 0; i < handles.size(); ++i) {
      handles[i] = (bindings[i] ? *bindings[i] : net_.dummy_).handle();
    }
    VkDescriptorSet set = net_.descriptor_set(handles);
    vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, net_.device_.pipeline(shader, net_.fp16_));
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, net_.device_.pipeline_layout(), 0, 1, &set, 0,
                            nullptr);
    vkCmdPushConstants(commands_, net_.device_.pipeline_layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       static_cast<uint32_t>(bytes), push);
    vkCmdDispatch(commands_, gx, gy, 1);
  }

  void copy(const View& src, const View& dst) {
    barrier();
    const VkDeviceSize e = net_.elem_;
    const VkBufferCopy region{static_cast<VkDeviceSize>(src.offset()) * e, static_cast<VkDeviceSize>(dst.offset()) * e,
                              static_cast<VkDeviceSize>(src.count()) * e};
    vkCmdCopyBuffer(commands_, src.buffer->handle(), dst.buffer->handle(), 1, &region);
  }
  void copy_raw(const Buffer& src, const Buffer& dst, std::size_t values) {
    barrier();
    const VkBufferCopy region{0, 0, values * net_.elem_};
    vkCmdCopyBuffer(commands_, src.handle(), dst.handle(), 1, &region);
  }
  // A copy of the zero buffer: vkCmdFillBuffer needs 4-byte alignment, which 16-bit values
  // at an odd offset do not have.
  void zero(const View& dst) {
    barrier();
    const VkBufferCopy region{0, static_cast<VkDeviceSize>(dst.offset()) * net_.elem_,
                              static_cast<VkDeviceSize>(dst.count()) * net_.elem_};
    vkCmdCopyBuffer(commands_, net_.zeros_.handle(), dst.buffer->handle(), 1, &region);
  }

  // out = act(conv(in) + bias (+ addend)); out.c must be the layer's output channels.
  void conv(const DeviceConv& w, const View& in, int stride, int pad, Act act, const View& out,
            const View* addend = nullptr) {
    const Conv2dParams p{in.c,
                         in.h,
                         in.w,
                         in.offset(),
                         out.c,
                         out.h,
                         out.w,
                         out.offset(),
                         w.kernel_h,
                         stride,
                         pad,
                         act,
                         w.weight.offset,
                         w.bias.offset,
                         addend ? addend->offset() : -1,
                         1.f};
    dispatch<Shader::conv2d>({&net_.weights_->buffer, in.buffer, out.buffer, addend ? addend->buffer : nullptr}, p,
                             tiles(static_cast<long>(out.h) * out.w, "a convolution"), tiles(out.c, "a convolution"));
  }

  // Token lists [features][tokens]: out = act(W · in + b).
  void linear(const DeviceLinear& w, const Buffer& in, int in_off, const Buffer& out, int out_off, int tokens,
              Act act = kActNone) {
    const MatmulParams p{w.out_features,  tokens,        w.in_features,
                         w.weight.offset, w.in_features, 1,
                         in_off,          tokens,        1,
                         out_off,         tokens,        1,
                         w.bias.offset,   act,           1.f};
    dispatch<Shader::matmul>({&net_.weights_->buffer, &in, &out, nullptr}, p, tiles(tokens, "attention"),
                             tiles(w.out_features, "attention"));
  }

  void matmul(const Buffer& a, const Buffer& b, const Buffer& c, const MatmulParams& p) {
    dispatch<Shader::matmul>({&a, &b, &c, nullptr}, p, tiles(p.n, "attention"), tiles(p.m, "attention"));
  }

  void resample(const View& src, const View& dst, int factor, bool relu, float scale) {
    const ResampleParams p{src.c, src.h, src.w, src.offset(), dst.offset(), factor, relu ? 1 : 0, scale};
    dispatch<Shader::resample>({src.buffer, nullptr, dst.buffer, nullptr}, p,
                               groups(static_cast<long>(dst.count()), kLocal));
  }

  void avgpool(const View& src, const View& dst) {
    const Avgpool2xParams p{src.c, src.h, src.w};
    dispatch<Shader::avgpool2x>({src.buffer, nullptr, dst.buffer, nullptr}, p,
                                groups(static_cast<long>(dst.count()), kLocal));
  }

  void axpby(float a, const View& x, float b, const View& y, const View& out) {
    const AxpbyParams p{out.count(), x.offset(), y.offset(), out.offset(), a, b};
    dispatch<Shader::axpby>({x.buffer, y.buffer, out.buffer, nullptr}, p, groups(out.count(), kLocal));
  }

  // Reads `v` back and hands it to the observer as NHWC (only when observing).
  void observe(const std::string& name, int frame, const View& v) {
    if (!observer_) {
      mark(name);
      return;
    }
    barrier();
    const VkDeviceSize e = net_.elem_;
    const VkBufferCopy region{static_cast<VkDeviceSize>(v.offset()) * e, 0, static_cast<VkDeviceSize>(v.count()) * e};
    vkCmdCopyBuffer(commands_, v.buffer->handle(), transfer_.readback.handle(), 1, &region);
    host_barrier();
    run();
    net_.staging_.resize(static_cast<std::size_t>(v.count()));
    net_.load(transfer_.readback.mapped(), net_.staging_.size(), net_.staging_.data());
    const float* planar = net_.staging_.data();
    const std::size_t plane = static_cast<std::size_t>(v.h) * v.w;
    nhwc_.resize(plane * v.c);
    for (int c = 0; c < v.c; ++c) {
      for (std::size_t p = 0; p < plane; ++p) nhwc_[p * v.c + c] = planar[c * plane + p];
    }
    (*observer_)(StageTensor{name, frame, v.h, v.w, v.c, nhwc_.data()});
    begin();
  }
  bool observing() const { return observer_ != nullptr; }

 private:
  VulkanNetwork& net_;
  VkCommandBuffer commands_;
  const StageObserver* observer_;
  std::vector<std::string>* marks_;
  const Transfer& transfer_;
  uint32_t query_base_;
  bool worked_ = false;  // commands recorded since the last timestamp
  std::vector<float> nhwc_;
};

VulkanNetwork::VulkanNetwork(std::shared_ptr<const DeviceWeights> weights, int height, int width)
    : weights_(std::move(weights)),
      device_(*weights_->device),
      fp16_(weights_->fp16),
      elem_(fp16_ ? 2 : 4),
      height_(height),
      width_(width),
      h8_(height / 8),
      w8_(width / 8),
      h16_(height / 16),
      w16_(width / 16),
      tokens_(h16_ * w16_) {
  block_rows_ = std::clamp(kScoreBlockFloats / std::max(tokens_, 1), 1, tokens_);
  const std::size_t hw = static_cast<std::size_t>(height) * width, hw8 = static_cast<std::size_t>(h8_) * w8_;
  const std::size_t l = tokens_;
  using M = VulkanDevice::Memory;
  const auto make = [&](std::size_t values, const char* what, M memory = M::device) {
    return device_.create_buffer(values * elem_, memory,
                                 std::string(what) + " at " + std::to_string(width) + "x" + std::to_string(height));
  };
  dummy_ = make(4, "a placeholder binding");
  zeros_ = make(kHiddenChannels * hw8 + 2, "zeros");
  for (std::size_t e = 0; e < ring_.size(); ++e) {
    ring_[e].upload = make(3 * hw, "the frame upload", M::upload);
    // Entry 0 also serves the observer, which reads whole stages back.
    ring_[e].readback =
        make(e == 0 ? std::max(kFeatureChannels * hw8, 2 * hw) : 2 * hw, "the read-back buffer", M::readback);
  }
  input_ = make(3 * hw, "the input frame");
  half_ = make(3 * hw / 4, "the 1/2 frame");
  quarter_ = make(3 * hw / 16, "the 1/4 frame");
  eighth_ = make(3 * hw / 64, "the 1/8 frame");
  encode_tmp_ = make(256 * hw8, "the backbone's scratch");
  cat8_ = make(384 * hw8, "the 1/8 concatenation");
  cat16_ = make(256 * l, "the 1/16 concatenation");
  for (auto& s : slots_) {
    s.f8 = make(kFeatureChannels * hw8, "frame features at 1/8");
    s.f16 = make(kFeatureChannels * l, "frame features at 1/16");
    s.up = make(128 * hw8, "the upsampler's frame features");
  }
  q_ = make(kDim * l, "attention queries");
  k_ = make(kDim * l, "attention keys");
  v_ = make(kDim * l, "attention values");
  scores_ = make(static_cast<std::size_t>(block_rows_) * l, "a block of attention scores");
  message_ = make(kDim * l, "attention messages");
  attn_tmp_ = make(kDim * l, "attention scratch");
  mlp_in_ = make(2 * kDim * l, "the attention MLP's input");
  mlp_hidden_ = make(2 * kDim * l, "the attention MLP's hidden layer");
  state0_ = make(kDim * l, "attention layer 0, frame 0");
  state1_ = make(kDim * l, "attention layer 0, frame 1");
  for (auto& a : attended_) a = make(kDim * l, "attention output");
  grid_ = make(2 * l, "the matching grid");
  correspondence_ = make(2 * l, "matching correspondences");
  flow16_ = make(2 * l, "flow at 1/16");
  flow8_ = make(2 * hw8, "flow at 1/8");
  const auto make_refine = [&](Refine& r, std::size_t plane) {
    r.input = make(kRefineDynamicChannels * plane, "the refinement input");
    r.constant_in = make(kRefineConstantChannels * plane, "the refinement's constant input");
    r.constant_out = make(kRefineHiddenWidth * plane, "the refinement's constant part");
    r.xa = make(kRefineHiddenWidth * plane, "refinement scratch");
    r.xb = make(kRefineHiddenWidth * plane, "refinement scratch");
    r.out66 = make(kRefineOutputChannels * plane, "the refinement output");
  };
  make_refine(refine16_, l);
  make_refine(refine8_, hw8);
  feature_in_ = make(2 * kMatchingChannels * hw8, "the 1/8 feature merge input");
  merge_tmp_ = make(kMatchingChannels * hw8, "merge scratch");
  context_in_ = make(2 * kContextChannels * hw8, "the context merge input");
  context_tmp_ = make(kContextChannels * hw8, "context merge scratch");
  for (auto& f : features8_) f = make(kMatchingChannels * hw8, "merged features at 1/8");
  upsample_in_ = make(130 * hw8, "the upsampler input");
  upsample1_ = make(256 * hw8, "the upsampler's first layer");
  upsample2_ = make(512 * hw8, "the upsampler's second layer");
  mask_ = make(kUpsampleMaskChannels * hw8, "the upsampling mask");
  flow_full_ = make(2 * hw, "the full-resolution flow");

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

// What no pass writes: the position channels of f16, the matching grid, the radius planes.
void VulkanNetwork::initialise_constants() {
  const std::size_t l = tokens_, hw8 = static_cast<std::size_t>(h8_) * w8_;
  // Positions (2·L), the grid (2·L), then radius planes (as many as the larger plane).
  std::vector<float> c(4 * l + hw8, kCorrRadiusPlane);
  for (int y = 0; y < h16_; ++y) {
    for (int x = 0; x < w16_; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w16_ + x;
      c[p] = static_cast<float>(y) - static_cast<float>(h16_) / 2.f;      // f16 position channel y
      c[l + p] = static_cast<float>(x) - static_cast<float>(w16_) / 2.f;  // f16 position channel x
      c[2 * l + p] = static_cast<float>(x);                               // grid x
      c[3 * l + p] = static_cast<float>(y);                               // grid y
    }
  }
  Buffer staging = device_.create_buffer(c.size() * elem_, VulkanDevice::Memory::upload, "constants");
  store(c.data(), c.size(), staging.mapped());
  const VkDeviceSize e = elem_;
  OneShotCommands commands(device_);
  VkCommandBuffer cb = commands.buffer();
  for (auto& s : slots_) {
    const VkBufferCopy pos{0, kBackbone16Channels * l * e, 2 * l * e};
    vkCmdCopyBuffer(cb, staging.handle(), s.f16.handle(), 1, &pos);
  }
  const VkBufferCopy grid{2 * l * e, 0, 2 * l * e};
  vkCmdCopyBuffer(cb, staging.handle(), grid_.handle(), 1, &grid);
  const VkBufferCopy radius16{4 * l * e, kContextChannels * l * e, l * e},
      radius8{4 * l * e, kContextChannels * hw8 * e, hw8 * e};
  vkCmdCopyBuffer(cb, staging.handle(), refine16_.constant_in.handle(), 1, &radius16);
  vkCmdCopyBuffer(cb, staging.handle(), refine8_.constant_in.handle(), 1, &radius8);
  vkCmdFillBuffer(cb, zeros_.handle(), 0, VK_WHOLE_SIZE, 0);
  commands.run();
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

VkDescriptorSet VulkanNetwork::descriptor_set(const std::array<VkBuffer, 4>& buffers) {
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
  std::array<VkDescriptorBufferInfo, 4> infos{};
  std::array<VkWriteDescriptorSet, 4> writes{};
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
  } catch (...) {
    vkFreeCommandBuffers(device_.handle(), pool_, 1, &pass.commands);
    throw;
  }
  return command_buffers_.emplace(key, std::move(pass)).first->second;
}

void VulkanNetwork::run(const Pass& pass) {
  device_.submit_and_wait(pass.commands, ring_[static_cast<std::size_t>(pass.entry)].fence);
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

void VulkanNetwork::read_flow(const Transfer& t, Tensor& out) {
  out.resize(height_, width_, 2);
  const std::size_t hw = static_cast<std::size_t>(height_) * width_;
  staging_.resize(2 * hw);
  load(t.readback.mapped(), staging_.size(), staging_.data());
  const float* planar = staging_.data();
  for (std::size_t p = 0; p < hw; ++p) {
    out.data[2 * p] = planar[p];
    out.data[2 * p + 1] = planar[hw + p];
  }
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
  if (observer && *observer) (*observer)(StageTensor{"flow", 0, height_, width_, 2, out.data.data()});
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
  started_.push_back({entry, &pass, pair});
  next_entry_ = (entry + 1) % kRing;
}

bool VulkanNetwork::finish(Tensor& out) {
  if (started_.empty()) throw std::logic_error("VulkanNetwork::finish: no step started");
  const Started s = started_.front();
  started_.pop_front();
  const Transfer& t = ring_[static_cast<std::size_t>(s.entry)];
  device_.wait(t.fence);
  read_stage_times(*s.pass);
  if (s.pair) read_flow(t, out);
  return s.pair;
}

void VulkanNetwork::record_encode(Recorder& r, int slot, const FrameLayout* frame) {
  const int h = height_, w = width_;
  const View input{&input_, 0, 3, h, w}, half{&half_, 0, 3, h / 2, w / 2}, quarter{&quarter_, 0, 3, h / 4, w / 4},
      eighth{&eighth_, 0, 3, h / 8, w / 8};
  if (frame) {
    const FrameU8Params p{frame->width, frame->height, w, h, frame->pad_left, frame->pad_top, frame->swap ? 1 : 0};
    r.dispatch<Shader::frame_u8>({&r.upload(), nullptr, &input_, nullptr}, p, groups(static_cast<long>(h) * w, kLocal));
  } else {
    r.copy_raw(r.upload(), input_, static_cast<std::size_t>(3) * h * w);
  }
  r.avgpool(input, half);
  r.avgpool(half, quarter);
  r.avgpool(quarter, eighth);
  const auto& wt = *weights_;
  Slot& s = slots_[static_cast<std::size_t>(slot)];
  const auto block = [&](const DeviceBlock& b, const View& in, int stride, int pad, const View& out) {
    const View tmp{&encode_tmp_, 0, b.conv1.out_channels, out.h, out.w};
    r.conv(b.conv1, in, stride, pad, kActLeakyRelu, tmp);
    r.conv(b.conv2, tmp, 1, 1, kActLeakyRelu, out);
  };
  const View cat8{&cat8_, 0, 384, h8_, w8_}, f8{&s.f8, 0, kFeatureChannels, h8_, w8_};
  block(wt.block_8_1, half, 4, 2, cat8.channels(0, 256));
  block(wt.block_8_2, quarter, 2, 2, cat8.channels(256, 128));
  block(wt.block_cat_8, cat8, 1, 1, f8);
  r.mark("backbone_s8");
  const View cat16{&cat16_, 0, 256, h16_, w16_};
  block(wt.block_16_1, eighth, 2, 2, cat16.channels(0, 128));
  block(wt.block_8_16, f8, 2, 2, cat16.channels(128, 128));
  block(wt.block_cat_16, cat16, 1, 1, View{&s.f16, 0, kBackbone16Channels, h16_, w16_});
  r.mark("backbone_s16");
  block(wt.conv_s8, input, 8, 0, View{&s.up, 0, 128, h8_, w8_});
  r.mark("conv_s8");
}

void VulkanNetwork::record_attention_layer(Recorder& r, const DeviceAttentionLayer& w, const Buffer& src,
                                           const Buffer& tgt, const Buffer& out) {
  const int l = tokens_;
  r.linear(w.q_proj, src, 0, q_, 0, l);  // already scaled by 1/sqrt(192)
  r.linear(w.k_proj, tgt, 0, k_, 0, l);
  r.linear(w.v_proj, tgt, 0, v_, 0, l);
  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    // scores[i][j] = q[:, r0 + i] · k[:, j]
    r.matmul(q_, k_, scores_, {n, l, kDim, r0, 1, l, 0, l, 1, 0, l, 1, -1, kActNone, 1.f});
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, &scores_, nullptr}, SoftmaxRowsParams{n, l, 0},
                                     static_cast<uint32_t>(n));
    // message[:, r0 + i] = v · scores[i]^T
    r.matmul(v_, scores_, message_, {kDim, n, l, 0, l, 1, 0, 1, l, r0, l, 1, -1, kActNone, 1.f});
  }
  r.linear(w.merge, message_, 0, attn_tmp_, 0, l);
  const auto layer_norm = [&](const DeviceLayerNorm& nw, const Buffer& x, const Buffer& dst, int dst_off,
                              const Buffer* residual) {
    const LayerNormParams p{kDim, l, 0, dst_off, residual ? 0 : -1, nw.gamma.offset, nw.beta.offset};
    r.dispatch<Shader::layer_norm>({&weights_->buffer, &x, &dst, residual}, p, groups(l, kLocal));
  };
  // mlp input = concat[src, LayerNorm1(merge(message))]
  layer_norm(w.norm1, attn_tmp_, mlp_in_, kDim * l, nullptr);
  r.copy(View{&src, 0, kDim, 1, l}, View{&mlp_in_, 0, kDim, 1, l});
  r.linear(w.mlp0, mlp_in_, 0, mlp_hidden_, 0, l, kActGelu);
  r.linear(w.mlp2, mlp_hidden_, 0, attn_tmp_, 0, l);
  layer_norm(w.norm2, attn_tmp_, out, 0, &src);
}

void VulkanNetwork::record_refinement(Recorder& r, const DeviceRefine& w, Refine& b, const View& f0, const View& f1,
                                      const View& flow, int iterations, const std::string& scale) {
  const int h = flow.h, wd = flow.w;
  const View input{&b.input, 0, kRefineDynamicChannels, h, wd};
  const View constant_out{&b.constant_out, 0, kRefineHiddenWidth, h, wd};
  r.conv(w.conv1_constant, View{&b.constant_in, 0, kRefineConstantChannels, h, wd}, 1, 1, kActNone, constant_out);
  r.zero(input.channels(kRefineHiddenOffset, kHiddenChannels));
  r.copy(flow, input.channels(kRefineFlowOffset, 2));
  const int inter = w.conv2.out_channels;
  for (int i = 0; i < iterations; ++i) {
    const LocalCorrelationParams cp{h, wd, f0.c, f0.offset(), f1.offset(), flow.offset(), 0};
    r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, &b.input, flow.buffer}, cp,
                                          groups(static_cast<long>(h) * wd, kLocal));
    const View xa{&b.xa, 0, kRefineHiddenWidth, h, wd};
    r.conv(w.conv1_dynamic, input, 1, 1, kActLeakyRelu, xa, &constant_out);
    View x{&b.xb, 0, inter, h, wd}, y{&b.xa, 0, inter, h, wd};
    r.conv(w.conv2, xa, 1, 1, kActLeakyRelu, x);
    for (const auto& layer : w.conv_layers) {
      r.conv(layer, x, 1, 1, kActLeakyRelu, y);
      std::swap(x, y);
    }
    const View out66{&b.out66, 0, kRefineOutputChannels, h, wd};
    r.conv(w.conv3, x, 1, 1, kActNone, out66);
    const RefineUpdateParams up{h * wd, input.channels(kRefineHiddenOffset, 1).offset(),
                                input.channels(kRefineFlowOffset, 1).offset(), flow.offset()};
    r.dispatch<Shader::refine_update>({&b.out66, nullptr, &b.input, flow.buffer}, up,
                                      groups(static_cast<long>(h) * wd, kLocal));
    const std::string it = "_iter" + std::to_string(i);
    if (!r.observing()) {
      r.mark("refine_" + scale + it);  // the observer's three tensors of an iteration are read at its end
    } else {
      r.observe("corr_" + scale + it, 0, input.channels(0, kCorrChannels));
      r.observe("refine_" + scale + it + "_hidden", 0, input.channels(kRefineHiddenOffset, kHiddenChannels));
      r.observe("refine_" + scale + it + "_delta", 0, out66.channels(0, 2));
    }
  }
}

void VulkanNetwork::record_flow(Recorder& r, int slot0, int slot1, const Iterations& iterations) {
  const Slot& s0 = slots_[static_cast<std::size_t>(slot0)];
  const Slot& s1 = slots_[static_cast<std::size_t>(slot1)];
  const auto& wt = *weights_;
  const int l = tokens_;
  r.observe("backbone_s16", 0, View{&s0.f16, 0, kFeatureChannels, h16_, w16_});
  r.observe("backbone_s16", 1, View{&s1.f16, 0, kFeatureChannels, h16_, w16_});
  r.observe("backbone_s8", 0, View{&s0.f8, 0, kFeatureChannels, h8_, w8_});
  r.observe("backbone_s8", 1, View{&s1.f8, 0, kFeatureChannels, h8_, w8_});
  r.observe("conv_s8", 0, View{&s0.up, 0, 128, h8_, w8_});

  // 1/16: cross-attention (layer 1 reads layer 0's outputs of both frames), then its BatchNorm.
  record_attention_layer(r, wt.attention[0], s0.f16, s1.f16, state0_);
  record_attention_layer(r, wt.attention[0], s1.f16, s0.f16, state1_);
  record_attention_layer(r, wt.attention[1], state0_, state1_, attended_[0]);
  record_attention_layer(r, wt.attention[1], state1_, state0_, attended_[1]);
  for (const auto& a : attended_) {
    const ChannelAffineParams p{kDim, l, 0, wt.attention_norm_scale.offset, wt.attention_norm_shift.offset};
    r.dispatch<Shader::channel_affine>({&wt.buffer, nullptr, &a, nullptr}, p, groups(kDim * l, kLocal));
  }
  const View att0{&attended_[0], 0, kDim, h16_, w16_}, att1{&attended_[1], 0, kDim, h16_, w16_};
  r.observe("cross_attn_s16", 0, att0);
  r.observe("cross_attn_s16", 1, att1);

  // Global matching: softmax(F0 F1^T / sqrt(128)) G - G, in blocks of rows.
  const View feat0 = att0.channels(kContextChannels, kMatchingChannels),
             feat1 = att1.channels(kContextChannels, kMatchingChannels);
  const float alpha = 1.f / std::sqrt(static_cast<float>(kMatchingChannels));
  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    r.matmul(attended_[0], attended_[1], scores_,
             {n, l, kMatchingChannels, feat0.offset() + r0, 1, l, feat1.offset(), l, 1, 0, l, 1, -1, kActNone, alpha});
    r.dispatch<Shader::softmax_rows>({nullptr, nullptr, &scores_, nullptr}, SoftmaxRowsParams{n, l, 0},
                                     static_cast<uint32_t>(n));
    r.matmul(grid_, scores_, correspondence_, {2, n, l, 0, l, 1, 0, 1, l, r0, l, 1, -1, kActNone, 1.f});
  }
  const View flow16{&flow16_, 0, 2, h16_, w16_};
  r.axpby(1.f, View{&correspondence_, 0, 2, h16_, w16_}, -1.f, View{&grid_, 0, 2, h16_, w16_}, flow16);
  r.observe("global_matching_flow", 0, flow16);

  // 1/16 refinement with ctx16 = relu(context of frame 0).
  r.resample(att0.channels(0, kContextChannels), View{&refine16_.constant_in, 0, kContextChannels, h16_, w16_}, 1, true,
             1.f);
  record_refinement(r, wt.refine_s16, refine16_, feat0, feat1, flow16, iterations.s16, "s16");

  // 1/16 → 1/8.
  const View flow8{&flow8_, 0, 2, h8_, w8_};
  r.resample(flow16, flow8, 2, false, 2.f);
  const std::array<const Slot*, 2> frames{&s0, &s1};
  for (int f = 0; f < 2; ++f) {
    const View in{&feature_in_, 0, 2 * kMatchingChannels, h8_, w8_};
    r.copy(View{&frames[f]->f8, kContextChannels, kMatchingChannels, h8_, w8_}, in.channels(0, kMatchingChannels));
    r.resample(View{&attended_[f], kContextChannels, kMatchingChannels, h16_, w16_},
               in.channels(kMatchingChannels, kMatchingChannels), 2, false, 1.f);
    const View tmp{&merge_tmp_, 0, kMatchingChannels, h8_, w8_};
    r.conv(wt.merge_s8_0, in, 1, 1, kActGelu, tmp);
    r.conv(wt.merge_s8_2, tmp, 1, 1, kActNone, View{&features8_[f], 0, kMatchingChannels, h8_, w8_});
  }
  r.observe("merge_s8", 0, View{&features8_[0], 0, kMatchingChannels, h8_, w8_});
  r.observe("merge_s8", 1, View{&features8_[1], 0, kMatchingChannels, h8_, w8_});
  const View ctx_in{&context_in_, 0, 2 * kContextChannels, h8_, w8_};
  r.resample(View{&s0.f8, 0, kContextChannels, h8_, w8_}, ctx_in.channels(0, kContextChannels), 1, true, 1.f);
  r.resample(att0.channels(0, kContextChannels), ctx_in.channels(kContextChannels, kContextChannels), 2, true, 1.f);
  const View ctx_tmp{&context_tmp_, 0, kContextChannels, h8_, w8_};
  r.conv(wt.context_merge_s8_0, ctx_in, 1, 1, kActGelu, ctx_tmp);
  const View ctx8{&refine8_.constant_in, 0, kContextChannels, h8_, w8_};
  r.conv(wt.context_merge_s8_2, ctx_tmp, 1, 1, kActNone, ctx8);
  r.observe("context_merge_s8", 0, ctx8);

  // 1/8 refinement.
  record_refinement(r, wt.refine_s8, refine8_, View{&features8_[0], 0, kMatchingChannels, h8_, w8_},
                    View{&features8_[1], 0, kMatchingChannels, h8_, w8_}, flow8, iterations.s8, "s8");

  // Convex upsampling.
  const View up_in{&upsample_in_, 0, 130, h8_, w8_};
  r.copy(flow8, up_in.channels(0, 2));
  r.copy(View{&s0.up, 0, 128, h8_, w8_}, up_in.channels(2, 128));
  const View u1{&upsample1_, 0, 256, h8_, w8_}, u2{&upsample2_, 0, 512, h8_, w8_},
      mask{&mask_, 0, kUpsampleMaskChannels, h8_, w8_};
  r.conv(wt.upsample_conv1, up_in, 1, 1, kActRelu, u1);
  r.conv(wt.upsample_conv2, u1, 1, 1, kActRelu, u2);
  r.conv(wt.upsample_conv3, u2, 1, 0, kActNone, mask);
  r.dispatch<Shader::convex_upsample>({&mask_, &flow8_, &flow_full_, nullptr}, ConvexUpsampleParams{h8_, w8_},
                                      groups(static_cast<long>(height_) * width_, kLocal));
  r.copy_raw(flow_full_, r.readback(), static_cast<std::size_t>(2) * height_ * width_);
  r.host_barrier();
  r.mark("flow");
}

}  // namespace neuflow::model::vulkan
