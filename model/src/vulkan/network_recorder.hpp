#pragma once
// What VulkanNetwork (buffers, the ring, recorded passes) and the ops that record the graph
// (ops/) share: the dispatch-size rules and the Recorder that writes one pass into a command
// buffer.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "graph/activation.hpp"
#include "graph/tensors.hpp"
#include "neuflow/model/device_work.hpp"
#include "vulkan/gemm_tile.hpp"
#include "vulkan/vulkan_network.hpp"

namespace neuflow::model::vulkan {

// The attention's and matching's score blocks hold at most this many floats (32 MiB), well
// inside lavapipe's 128 MiB per buffer, so memory stays O(L · block) at any size.
inline constexpr int kScoreBlockFloats = 8 << 20;
inline constexpr int kLocal = 256;  // invocations per workgroup of the element-wise shaders

// The activation's code in shaders/params/activation.h.
inline int activation_code(Activation act) {
  switch (act) {
    case Activation::none: return kActNone;
    case Activation::leaky_relu: return kActLeakyRelu;
    case Activation::relu: return kActRelu;
    case Activation::gelu: return kActGelu;
  }
  return kActNone;
}

// Element-wise shaders loop over what a capped dispatch does not cover (common.glsl).
inline uint32_t groups(long count, long per_group) {
  return static_cast<uint32_t>(std::clamp<long>((count + per_group - 1) / per_group, 1, 65535));
}

// The tiled products do not loop: each workgroup is one tile (64 wide unless `per_group` says
// otherwise), so the grid must fit.
inline uint32_t tiles(long count, const char* what, long per_group = 64) {
  const long n = (count + per_group - 1) / per_group;
  if (n > 65535) {
    throw BackendError(BackendError::Kind::unavailable, std::string("a model size too large for one dispatch of ") +
                                                            what + ": choose a smaller model-width/model-height");
  }
  return static_cast<uint32_t>(std::max<long>(n, 1));
}

// What a command moves and computes: the bytes of the tensors it reads and writes, each once,
// and its multiply-adds, from its shapes (DeviceWork).
struct Work {
  long long read = 0, written = 0, multiply_adds = 0;
};

// Records one pass. A command gets a barrier before it only where it depends on what came
// before: it reads or writes a buffer written since the last barrier, or writes one read since
// (the descriptors bind whole buffers, so whole buffers are what is tracked; which bindings a
// shader reads and writes comes from its SPIR-V). A recording's first command always gets one,
// which orders it after the queue's earlier submissions. With an observer, observe() ends the
// command buffer, runs it, reads the tensor back and goes on in a fresh recording. What the
// pass asks of the device is counted as it is recorded (work()).
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
      write_timestamp(query_base_);
    }
  }

  const Buffer& upload() const { return transfer_.upload; }
  // Where the pass's flow goes for the host (Transfer::flow), and the tensor whose values were
  // last written there (-1: none yet).
  const Buffer& flow_out() const { return transfer_.flow; }
  void handed_out(graph::TensorId tensor) { handed_out_ = tensor; }
  graph::TensorId handed_out() const { return handed_out_; }
  const DeviceWork& work() const { return work_; }
  // Bytes of `values` tensor values in the pass's precision.
  long long bytes(long long values) const { return values * static_cast<long long>(net_.elem_); }

  // The end of the stage `name`: a timestamp once everything recorded before it has run.
  // Consecutive names without work between them (the backbone's outputs that the flow pass
  // only reads) take no timestamp.
  void mark(std::string_view name) {
    for (std::size_t i = labelled_; i < work_.commands.size(); ++i) work_.commands[i].stage = name;
    labelled_ = work_.commands.size();
    if (!marks_ || !worked_ || marks_->size() + 1 >= kTimestamps) return;
    marks_->emplace_back(name);
    write_timestamp(query_base_ + static_cast<uint32_t>(marks_->size()));
    worked_ = false;
  }

  void begin() {
    net_.device_.check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    net_.device_.check(vkBeginCommandBuffer(commands_, &info), "vkBeginCommandBuffer");
    after_unknown_ = true;
  }
  void end() { net_.device_.check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer"); }
  void run() {
    end();
    net_.device_.submit_and_wait(commands_, transfer_.fence);
  }

  // What `stage` wrote (a copy, or a shader), visible to the host once the pass's fence signals.
  void host_barrier(VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask =
        stage == VK_PIPELINE_STAGE_TRANSFER_BIT ? VK_ACCESS_TRANSFER_WRITE_BIT : VK_ACCESS_SHADER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, stage, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &b, 0, nullptr, 0, nullptr);
    ++work_.barriers;
  }

  // S's push constants are its params header's struct (ShaderParams), so recording a shader with
  // another's parameters does not compile.
  template <Shader S>
  void dispatch(std::array<const Buffer*, kShaderBindings> bindings, const typename ShaderParams<S>::type& push,
                const Work& work, uint32_t gx, uint32_t gy = 1, uint32_t gz = 1) {
    record_dispatch(S, bindings, &push, sizeof push, work, {gx, gy, gz});
  }

  // A product (conv2d, matmul or winograd_gemm) of m × n outputs, `batches` times, on the
  // kernels the network runs its products on (product_kernels.hpp): every variant takes the
  // scalar shader's parameters, in the tile gemm_tile_for() chooses (or `tile`, for a product
  // whose epilogue needs that one). `what` names the layer in a too-large-for-one-dispatch error.
  template <Shader S>
  void product(std::array<const Buffer*, kShaderBindings> bindings, const typename ShaderParams<S>::type& push,
               const Work& work, long m, long n, const char* what, uint32_t batches = 1,
               std::optional<GemmTile> chosen = std::nullopt) {
    const GemmTile tile = chosen ? *chosen : gemm_tile_for(m, n, batches, net_.gemm_tiles_);
    record_dispatch(product_shader(S, net_.products_), bindings, &push, sizeof push, work,
                    {tiles(n, what, tile.columns()), tiles(m, what, tile.rows()), batches}, tile);
  }

  // The next dispatch touches only `v`'s values of its binding `binding`, not all of that buffer:
  // for a kernel that reads or writes exactly that view there, so that dispatches on other values
  // of the same buffer (the two halves of a concatenation, tensors of one memory region) need no
  // barrier between them.
  void touches_only(std::size_t binding, const View& v) {
    const VkDeviceSize e = net_.elem_;
    exact_.at(binding) = Span{v.buffer->handle(), static_cast<VkDeviceSize>(v.offset()) * e,
                              static_cast<VkDeviceSize>(v.offset() + v.count()) * e};
  }

  // `tile`: a product's (its kernel's specialization); other shaders have none.
  void record_dispatch(Shader shader, std::array<const Buffer*, kShaderBindings> bindings, const void* push,
                       std::size_t bytes, const Work& work, std::array<uint32_t, 3> grid, GemmTile tile = kGemmTile64) {
    std::array<VkBuffer, kShaderBindings> handles{};
    std::vector<Span> reads, writes;
    const auto& access = shader_info(shader).bindings;
    for (std::size_t i = 0; i < handles.size(); ++i) {
      handles[i] = (bindings[i] ? *bindings[i] : net_.dummy_).handle();
      const Span touched = exact_[i] ? *exact_[i] : whole(handles[i]);
      if (touched.buffer != handles[i]) {
        throw std::logic_error(std::string("the Vulkan ") + shader_name(shader) + "'s binding " + std::to_string(i) +
                               " is not the buffer its touched values lie in");
      }
      if (access[i].reads) reads.push_back(touched);
      if (access[i].writes) writes.push_back(touched);
    }
    exact_ = {};
    order(reads, writes);
    VkDescriptorSet set = net_.descriptor_set(handles);
    vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, net_.device_.pipeline(shader, net_.fp16_, tile));
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, net_.device_.pipeline_layout(), 0, 1, &set, 0,
                            nullptr);
    vkCmdPushConstants(commands_, net_.device_.pipeline_layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       static_cast<uint32_t>(bytes), push);
    vkCmdDispatch(commands_, grid[0], grid[1], grid[2]);
    ++work_.dispatches;
    count(shader_name(shader), static_cast<std::uint64_t>(grid[0]) * grid[1] * grid[2], work);
  }

  void copy(const View& src, const View& dst) {
    const VkDeviceSize e = net_.elem_;
    copy_region(*src.buffer, *dst.buffer,
                {static_cast<VkDeviceSize>(src.offset()) * e, static_cast<VkDeviceSize>(dst.offset()) * e,
                 static_cast<VkDeviceSize>(src.count()) * e});
  }
  void copy_raw(const Buffer& src, const Buffer& dst, std::size_t values) {
    copy_region(src, dst, {0, 0, values * net_.elem_});
  }
  // A copy of the zero buffer: vkCmdFillBuffer needs 4-byte alignment, which 16-bit values
  // at an odd offset do not have.
  void zero(const View& dst) {
    copy_region(
        net_.zeros_, *dst.buffer,
        {0, static_cast<VkDeviceSize>(dst.offset()) * net_.elem_, static_cast<VkDeviceSize>(dst.count()) * net_.elem_});
  }

  // out = softmax(alpha · qᵀ k) · vᵀ per query token (flash_attention.comp), less v at the
  // query's own token where `subtract_own_value`. `across_frames`: the tensors hold two frames'
  // tokens (frame 0's rows above frame 1's), each frame's queries against the other's keys.
  void flash_attention(const View& q, const View& k, const View& v, const View& out, float alpha,
                       bool subtract_own_value, bool across_frames = false) {
    const int frames = across_frames ? 2 : 1;
    const int plane = q.h * q.w, tokens = plane / frames;
    if (q.c > kFlashAttentionMaxChannels || v.c > kFlashAttentionMaxChannels) {
      throw std::logic_error("the Vulkan attention takes at most " + std::to_string(kFlashAttentionMaxChannels) +
                             " channels");
    }
    const FlashAttentionParams p{tokens,
                                 q.c,
                                 v.c,
                                 q.offset(),
                                 k.offset(),
                                 v.offset(),
                                 out.offset(),
                                 plane,
                                 across_frames ? tokens : 0,
                                 across_frames ? tokens : 0,
                                 across_frames ? -tokens : 0,
                                 subtract_own_value ? 1 : 0,
                                 alpha};
    dispatch<Shader::flash_attention>({q.buffer, k.buffer, out.buffer, v.buffer}, p,
                                      {bytes(q.count() + k.count() + v.count()), bytes(out.count()),
                                       static_cast<long long>(frames) * tokens * tokens * (q.c + v.c)},
                                      groups(tokens, 64), static_cast<uint32_t>(frames));
  }

  // Copies `rows` rows of each of in's channels from row `in_row` on into out's from `out_row`
  // (tensors of one width): one copy command, a region a channel.
  void copy_rows(const View& in, const View& out, int in_row, int out_row, int rows) {
    const VkDeviceSize e = net_.elem_;
    std::vector<VkBufferCopy> regions(static_cast<std::size_t>(in.c));
    for (int c = 0; c < in.c; ++c) {
      regions[static_cast<std::size_t>(c)] = {
          static_cast<VkDeviceSize>(in.offset() + static_cast<long long>(c) * in.h * in.w + in_row * in.w) * e,
          static_cast<VkDeviceSize>(out.offset() + static_cast<long long>(c) * out.h * out.w + out_row * out.w) * e,
          static_cast<VkDeviceSize>(rows) * in.w * e};
    }
    copy_regions(*in.buffer, *out.buffer, regions);
  }

  // The pass's frames: the slot that holds the frame each graph::FrameRole names (-1: none).
  void bind_frames(std::array<int, 3> slots) { frames_ = slots; }
  // An encode pass's source: an 8-bit frame in the upload (its layout), or nullptr for floats.
  void set_frame_layout(const FrameLayout* layout) { frame_layout_ = layout; }
  const FrameLayout* frame_layout() const { return frame_layout_; }

  // A slice of the graph's tensors in this pass's memory.
  View view(const graph::Slice& s) const {
    const graph::TensorDesc& d = net_.graph_.tensors.at(s.tensor);
    return {&net_.buffer_of(s.tensor, frames_), s.channel, s.c, d.h, d.w};
  }
  const graph::TensorTable& tensors() const { return net_.graph_.tensors; }
  const Buffer& weights() const { return net_.weights_->buffer; }
  const DeviceWeights& device_weights() const { return *net_.weights_; }
  // How the stride-1 3×3 convolutions run (conv_algorithm.hpp).
  ConvAlgorithm conv_algorithm() const { return net_.conv_; }
  // What the products run on (product_kernels.hpp).
  ProductKernels product_kernels() const { return net_.products_; }
  bool fp16() const { return net_.fp16_; }  // the tensors' precision
  // F(4×4, 3×3)'s transformed input tiles and their products (fp32), which the split Winograd
  // convolutions use in turn.
  const Buffer& winograd_points() const { return net_.winograd_points_; }
  const Buffer& winograd_products() const { return net_.winograd_products_; }
  int height() const { return net_.height_; }
  int width() const { return net_.width_; }

  // Copies `v` to the start of the observer's read-back buffer, for the host once the commands
  // so far have run.
  void read_back(const View& v) {
    const VkDeviceSize e = net_.elem_;
    copy_region(*v.buffer, net_.observed_,
                {static_cast<VkDeviceSize>(v.offset()) * e, 0, static_cast<VkDeviceSize>(v.count()) * e});
    host_barrier();
  }

  // Reads `v` back and hands it to the observer as NHWC (only when observing).
  void observe(std::string_view name, int frame, const View& v) {
    if (!observer_) {
      mark(name);
      return;
    }
    read_back(v);
    run();
    net_.staging_.resize(static_cast<std::size_t>(v.count()));
    net_.load(net_.observed_.mapped(), net_.staging_.size(), net_.staging_.data());
    const float* planar = net_.staging_.data();
    const std::size_t plane = static_cast<std::size_t>(v.h) * v.w;
    nhwc_.resize(plane * v.c);
    for (int c = 0; c < v.c; ++c) {
      for (std::size_t p = 0; p < plane; ++p) nhwc_[p * v.c + c] = planar[c * plane + p];
    }
    const std::string stage_name(name);
    (*observer_)(StageTensor{stage_name, frame, v.h, v.w, v.c, nhwc_.data()});
    begin();
  }
  bool observing() const { return observer_ != nullptr; }

 private:
  void barrier() {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                      VK_ACCESS_TRANSFER_WRITE_BIT;
    const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vkCmdPipelineBarrier(commands_, stages, stages, 0, 1, &b, 0, nullptr, 0, nullptr);
    ++work_.barriers;
  }

  // Bytes [begin, end) of a buffer: a dispatch touches its bindings whole (the descriptors bind
  // whole buffers), a copy only its regions.
  struct Span {
    VkBuffer buffer;
    VkDeviceSize begin, end;
  };
  static Span whole(VkBuffer b) { return {b, 0, VK_WHOLE_SIZE}; }

  // A barrier before the next command where it depends on one since the last barrier: reads
  // bytes written since, or writes bytes read or written since.
  void order(const std::vector<Span>& reads, const std::vector<Span>& writes) {
    const auto in = [](const std::vector<Span>& set, const Span& s) {
      return std::any_of(set.begin(), set.end(),
                         [&](const Span& t) { return t.buffer == s.buffer && t.begin < s.end && s.begin < t.end; });
    };
    bool depends = after_unknown_;
    for (const Span& b : reads) depends = depends || in(written_, b);
    for (const Span& b : writes) depends = depends || in(written_, b) || in(read_, b);
    if (depends) {
      barrier();
      barrier_before_ = true;
      written_.clear();
      read_.clear();
      after_unknown_ = false;
    }
    read_.insert(read_.end(), reads.begin(), reads.end());
    written_.insert(written_.end(), writes.begin(), writes.end());
    worked_ = true;
  }

  void copy_region(const Buffer& src, const Buffer& dst, const VkBufferCopy& region) {
    copy_regions(src, dst, {&region, 1});
  }
  // One copy command, its barrier by the bytes its regions read and write.
  void copy_regions(const Buffer& src, const Buffer& dst, std::span<const VkBufferCopy> regions) {
    std::vector<Span> reads, writes;
    long long n = 0;
    for (const VkBufferCopy& region : regions) {
      reads.push_back({src.handle(), region.srcOffset, region.srcOffset + region.size});
      writes.push_back({dst.handle(), region.dstOffset, region.dstOffset + region.size});
      n += static_cast<long long>(region.size);
    }
    order(reads, writes);
    vkCmdCopyBuffer(commands_, src.handle(), dst.handle(), static_cast<uint32_t>(regions.size()), regions.data());
    ++work_.copies;
    count("copy", 0, {n, n, 0});
  }

  void count(std::string kernel, std::uint64_t workgroups, const Work& w) {
    work_.commands.push_back({std::move(kernel),
                              {},
                              workgroups,
                              static_cast<std::uint64_t>(w.read),
                              static_cast<std::uint64_t>(w.written),
                              static_cast<std::uint64_t>(w.multiply_adds),
                              barrier_before_});
    barrier_before_ = false;
  }

  void write_timestamp(uint32_t query) {
    vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, net_.timestamps_, query);
    ++work_.timestamps;
  }

  VulkanNetwork& net_;
  VkCommandBuffer commands_;
  const StageObserver* observer_;
  std::vector<std::string>* marks_;
  const Transfer& transfer_;
  uint32_t query_base_;
  bool worked_ = false;  // commands recorded since the last timestamp
  DeviceWork work_;
  std::size_t labelled_ = 0;  // commands before this one have their stage
  graph::TensorId handed_out_ = -1;
  // What was written and read since the last barrier; after_unknown_: nothing is known of what
  // ran before (a recording's start), so the next command waits for all of it.
  std::vector<Span> written_, read_;
  std::array<std::optional<Span>, kShaderBindings> exact_;  // touches_only(), for the next dispatch
  bool after_unknown_ = true;
  bool barrier_before_ = false;  // the command being recorded waits for those before it
  std::array<int, 3> frames_{-1, -1, -1};
  const FrameLayout* frame_layout_ = nullptr;
  std::vector<float> nhwc_;
};

}  // namespace neuflow::model::vulkan
