#pragma once
// The whole forward pass on a Vulkan device at one model resolution: the network graph's ops
// recorded into command buffers (ops/: one file per op), its tensors in buffers planned from
// their live ranges. Every buffer, descriptor set and command buffer is created once here; a
// pass replays a command buffer recorded the first time that pass (encode into a slot, or flow
// between two slots with given iterations) was asked for. With an observer the pass is recorded anew, stopping at every named stage to
// read it back. Without one, a recorded pass writes a GPU timestamp after each named stage
// (where the queue has timestamps), so every pass also measures where its time went.
//
// Streaming can be pipelined: start() writes a frame into the next entry of a ring of
// host-visible upload and read-back buffers and queues its encoding and its pair in one
// submission without waiting, so the host uploads frame N+1 (and reads back pair N-1) while
// the device computes pair N. The device runs submissions in order (each pass begins with a
// barrier), so only what the host touches needs a copy per ring entry.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "graph/memory_plan.hpp"
#include "graph/network_graph.hpp"
#include "inference_backend.hpp"
#include "neuflow/model/device_work.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/model/stage_observer.hpp"
#include "tensor.hpp"
#include "vulkan/conv_algorithm.hpp"
#include "vulkan/device_weights.hpp"
#include "vulkan/gemm_tile.hpp"
#include "vulkan/product_kernels.hpp"

namespace neuflow::model::vulkan {

// A channel range of a planar [C][H][W] tensor in a device buffer.
struct View {
  const Buffer* buffer = nullptr;
  int channel = 0;  // first channel
  int c = 0, h = 0, w = 0;
  int offset() const { return channel * h * w; }  // in floats
  int count() const { return c * h * w; }
  View channels(int first, int n) const { return {buffer, channel + first, n, h, w}; }
};

class VulkanNetwork {
 public:
  static constexpr int kSlots = InferenceBackend::kSlots;  // frame features kept on the device

  // height, width: multiples of 16, at least 32. products: the kernels its products run on
  // (product_kernels_for()); conv: how the Winograd layers run where the weights have
  // transformed filters (conv_algorithm_for()); gemm_tiles: how the scalar products choose
  // their tiles (gemm_tiles_for()). Throws BackendError (e.g. out of memory).
  VulkanNetwork(std::shared_ptr<const DeviceWeights> weights, int height, int width,
                ProductKernels products = ProductKernels::scalar, ConvAlgorithm conv = ConvAlgorithm::winograd_fused,
                GemmTiles gemm_tiles = {});
  ~VulkanNetwork();
  VulkanNetwork(const VulkanNetwork&) = delete;
  VulkanNetwork& operator=(const VulkanNetwork&) = delete;

  int height() const { return height_; }
  int width() const { return width_; }

  // image: [height, width, 3] NHWC in 0..1, as the CPU backend takes it.
  void encode(const Tensor& image, int slot);
  // An 8-bit interleaved frame no larger than the model size, converted on the device: centred
  // at (pad_left, pad_top) in edge-replicated padding, its first and third channels exchanged
  // when `swap`; what prepare_input() does in padding mode.
  struct FrameLayout {  // an 8-bit frame's size, where it sits in the input, its channel order
    int width, height, pad_left, pad_top;
    bool swap;
  };
  struct Frame {
    const std::uint8_t* data;
    std::ptrdiff_t stride;
    FrameLayout layout;
  };
  void encode(const Frame& frame, int slot);
  // out: [height, width, 2] NHWC.
  void flow(int slot0, int slot1, const Iterations& iterations, Tensor& out, const StageObserver* observer);
  // The device time of each named stage of the passes run since the last call (none for a
  // pass with an observer, or on a queue without timestamps).
  std::vector<StageTime> take_stage_times() { return std::exchange(stage_times_, {}); }
  // What the passes run since the last call asked of the device (none for a pass with an
  // observer): their commands as recorded, and the submissions and host waits that ran them.
  DeviceWork take_device_work() { return std::exchange(work_, {}); }

  // Ring entries: passes started and not yet finished.
  static constexpr int kRing = 2;
  struct Step {
    const Frame* frame = nullptr;   // the frame in 8 bits, or
    const Tensor* image = nullptr;  // converted as encode(Tensor) takes it
    int slot = 0;                   // where its features go
    int previous = -1;              // the slot of the frame before it; -1: no pair
    Iterations iterations;
  };
  // Queues the step; std::logic_error when kRing steps are started and not finished. The
  // synchronous calls above need none outstanding (std::logic_error).
  void start(const Step& step);
  // Waits for the oldest started step; its flow into `out` ([height, width, 2]) when it had
  // a pair (true). The step is finished even when this throws (a lost device).
  bool finish(Tensor& out);
  int started() const { return static_cast<int>(started_.size()); }

  class Recorder;

 private:
  // A recorded pass: the stage after which each of its timestamps 1.. is written (0: its start),
  // in the query range of the ring entry it was recorded for.
  struct Pass {
    VkCommandBuffer commands = VK_NULL_HANDLE;
    std::vector<std::string> marks;
    int entry = 0;
    DeviceWork work;  // its commands, counted when it was recorded
  };
  // What the host writes and reads while the device works: one per ring entry. The
  // synchronous calls use entry 0.
  // `flow`: the pass's flow as the host hands it on ([height][width][2] fp32), written by the
  // convex upsampling's dispatch.
  struct Transfer {
    Buffer upload, flow;
    VkFence fence = VK_NULL_HANDLE;
  };
  struct Started {
    int entry;
    const Pass* pass;
    bool pair;
  };
  static constexpr uint32_t kTimestamps = 1024;  // per ring entry; stages past it are not timed
  // frame: the upload holds an 8-bit frame; nullptr: the upload holds the input as floats.
  void record_encode(Recorder& r, int slot, const FrameLayout* frame);
  void record_flow(Recorder& r, int slot0, int slot1, const Iterations& iterations);
  void record(Recorder& r, const graph::OpList<DeviceTensor>& ops);
  // The flow ops for these iterations, checked once against the memory plan.
  const graph::OpList<DeviceTensor>& flow_ops(const Iterations& iterations);
  // `frames`: the slot of each graph::FrameRole in the pass.
  const Buffer& buffer_of(graph::TensorId tensor, const std::array<int, 3>& frames) const;
  void allocate_tensors();
  // entry: the ring entry whose buffers and timestamps the pass uses.
  const Pass& cached(const std::string& key, int entry, const std::function<void(Recorder&)>& record);
  void run(const Pass& pass);
  void read_stage_times(const Pass& pass);
  void fill_upload(const Transfer& t, const Frame* frame, const Tensor* image);
  void read_flow(const Transfer& t, Tensor& out);
  void require_idle(const char* call) const;
  static std::string encode_key(const FrameLayout* frame);
  VkDescriptorSet descriptor_set(const std::array<VkBuffer, kShaderBindings>& buffers);
  void initialise_constants();
  void release_handles();
  // Host values to and from the device's storage type.
  void store(const float* values, std::size_t count, void* device_memory) const;
  void load(const void* device_memory, std::size_t count, float* values) const;

  std::shared_ptr<const DeviceWeights> weights_;
  VulkanDevice& device_;
  bool fp16_;  // tensors stored as float16_t
  ProductKernels products_;
  ConvAlgorithm conv_;  // split Winograd goes through the two buffers below
  GemmTiles gemm_tiles_;
  std::size_t elem_;  // bytes per stored value: 4 or 2
  int height_, width_, tokens_, block_rows_;

  Buffer dummy_, zeros_;
  Buffer winograd_points_, winograd_products_;  // sized for the largest split Winograd convolution
  std::array<Transfer, kRing> ring_;
  int next_entry_ = 0;
  std::deque<Started> started_;
  std::vector<float> staging_;  // host-side frame or read-back, as floats
  // Planned with graph::kPlanIterations; the flow ops of other iterations are built and checked
  // against the plan when first asked for.
  graph::NetworkGraph<DeviceTensor> graph_;
  graph::MemoryPlan plan_;
  std::map<std::pair<int, int>, graph::OpList<DeviceTensor>> flow_ops_;
  std::vector<Buffer> regions_;                               // the transient tensors'
  std::map<graph::TensorId, Buffer> persistent_;              // by tensor
  std::array<std::map<std::string, Buffer>, kSlots> frames_;  // each slot's frame tensors, by name

  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorPool> descriptor_pools_;
  std::map<std::array<VkBuffer, kShaderBindings>, VkDescriptorSet> descriptor_sets_;
  std::map<std::string, Pass> command_buffers_;
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  std::vector<uint64_t> timestamp_values_;
  std::vector<StageTime> stage_times_;
  DeviceWork work_;
  VkCommandBuffer observed_commands_ = VK_NULL_HANDLE;
  Buffer observed_;  // where an observer's tensors are read back, one at a time
};

}  // namespace neuflow::model::vulkan
