#include "vulkan/device_weights.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "vulkan/half_float.hpp"
#include "vulkan/one_shot_commands.hpp"
#include "winograd/winograd_f43.hpp"

namespace neuflow::model::vulkan {

namespace {

// G g Gᵀ for every (out, in) pair of a 3×3 convolution, as [36][out][in] (point 6·i + j of
// the 6×6 result at i·6 + j) with out and in padded with zeros to multiples of 16 (a tensor-core
// fragment's side), computed in double as the CPU backend's filters are.
std::vector<float> winograd_f43_filters(const ConvWeights& conv) {
  const int out = conv.out_channels, in = conv.in_channels;
  const int out_pad = winograd_filter_side(out), in_pad = winograd_filter_side(in);
  std::vector<float> u(static_cast<std::size_t>(36) * out_pad * in_pad, 0.f);
  for (int o = 0; o < out; ++o) {
    for (int i = 0; i < in; ++i) {
      double g[9], columns[18], points[36];
      for (int k = 0; k < 9; ++k) g[k] = conv.weight[(static_cast<std::size_t>(o) * in + i) * 9 + k];
      for (int x = 0; x < 3; ++x) winograd::F43::filter_1d(g + x, columns + x, 3, 3);  // G g: [6][3]
      for (int r = 0; r < 6; ++r) winograd::F43::filter_1d(columns + 3 * r, points + 6 * r, 1, 1);
      for (int k = 0; k < 36; ++k) {
        u[(static_cast<std::size_t>(k) * out_pad + o) * in_pad + i] = static_cast<float>(points[k]);
      }
    }
  }
  return u;
}

// Tensors laid out in one host vector; offsets are in floats.
// `alignment` (in values) keeps every tensor's start 16-byte aligned: 4 values do in fp32 (vector
// loads on some GPUs); the Winograd filters, whose fragments tensor cores load, take 16, which
// does in fp16 too.
struct Packed {
  explicit Packed(std::size_t values_aligned) : alignment(values_aligned) {}
  int add(const std::vector<float>& values) {
    const int offset = static_cast<int>(data.size());
    data.insert(data.end(), values.begin(), values.end());
    while (data.size() % alignment != 0) data.push_back(0.f);
    return offset;
  }
  std::size_t alignment;
  std::vector<float> data;
};

// map_weights()'s function: each host tensor appended, its offset kept; none stays none. With
// Winograd, each 3×3 convolution's filters are also appended transformed, to a vector of their
// own: four times the size of the filters, they would take the weights' buffer past the 128 MiB
// that many devices allow one storage buffer.
struct Packer {
  DeviceTensor operator()(const std::vector<float>& values) {
    return values.empty() ? DeviceTensor{} : DeviceTensor{weights.add(values)};
  }
  void convolution(const ConvWeights& host, const DeviceConv& device) {
    if (!winograd || host.kernel_h != 3 || host.kernel_w != 3) return;
    winograd_filters.emplace(device.weight.offset, filters.add(winograd_f43_filters(host)));
  }
  bool winograd = false;
  Packed weights{4}, filters{16};
  std::map<int, int> winograd_filters;
};

// upsample_conv3's filters and bias reordered as DeviceWeights::convex_mask describes.
std::pair<std::vector<float>, std::vector<float>> convex_mask_rows(const ConvWeights& conv) {
  constexpr int kGroups = DeviceWeights::kConvexTileRows / 9, kSubpixels = 64;
  const auto in = static_cast<std::size_t>(conv.in_channels);  // 1×1
  if (conv.out_channels != 9 * kSubpixels || conv.kernel_h != 1 || conv.kernel_w != 1) {
    throw std::logic_error("the upsampler's mask convolution is not 1x1 with 576 outputs");
  }
  std::vector<float> weight(static_cast<std::size_t>(DeviceWeights::kConvexRows) * in, 0.f);
  std::vector<float> bias(DeviceWeights::kConvexRows, 0.f);
  for (int row = 0; row < DeviceWeights::kConvexRows; ++row) {
    const int tile = row / DeviceWeights::kConvexTileRows, r = row % DeviceWeights::kConvexTileRows;
    const int g = r / 9, k = r % 9, s = tile * kGroups + g;
    if (g >= kGroups || s >= kSubpixels) continue;
    const std::size_t from = static_cast<std::size_t>(k) * kSubpixels + static_cast<std::size_t>(s);
    std::copy_n(conv.weight.begin() + static_cast<std::ptrdiff_t>(from * in), in,
                weight.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(row) * in));
    if (!conv.bias.empty()) bias[static_cast<std::size_t>(row)] = conv.bias[from];
  }
  return {std::move(weight), std::move(bias)};
}

// `values` in a device buffer of their own, in the tensors' precision.
Buffer upload_values(VulkanDevice& device, const std::vector<float>& values, bool fp16, const std::string& what) {
  const std::size_t bytes = std::max<std::size_t>(values.size(), 1) * (fp16 ? 2 : 4);
  Buffer buffer = device.create_buffer(bytes, VulkanDevice::Memory::device, what);
  Buffer staging = device.create_buffer(bytes, VulkanDevice::Memory::upload, "uploading " + what);
  if (fp16) {
    auto* out = static_cast<std::uint16_t*>(static_cast<void*>(staging.mapped()));
    for (std::size_t i = 0; i < values.size(); ++i) out[i] = to_half(values[i]);
  } else if (!values.empty()) {  // none: direct convolutions have no transformed filters
    std::memcpy(staging.mapped(), values.data(), values.size() * sizeof(float));
  }
  OneShotCommands commands(device);
  const VkBufferCopy region{0, 0, bytes};
  vkCmdCopyBuffer(commands.buffer(), staging.handle(), buffer.handle(), 1, &region);
  commands.run();
  return buffer;
}

std::shared_ptr<const DeviceWeights> upload(const std::shared_ptr<const FlowModel>& model,
                                            const std::shared_ptr<VulkanDevice>& device, bool fp16, bool winograd) {
  auto d = std::make_shared<DeviceWeights>();
  d->model = model;
  d->device = device;
  d->fp16 = fp16;
  Packer p;
  p.winograd = winograd;
  map_weights(model->weights(), p, *d);
  const ConvWeights& mask = model->weights().upsample_conv3;
  const auto [weight, bias] = convex_mask_rows(mask);
  d->convex_mask = d->upsample_conv3;
  d->convex_mask.out_channels = DeviceWeights::kConvexRows;
  d->convex_mask.weight = DeviceTensor{p.weights.add(weight)};
  d->convex_mask.bias = DeviceTensor{p.weights.add(bias)};
  d->buffer = upload_values(*device, p.weights.data, fp16, "the model's weights");
  d->winograd_filters = std::move(p.winograd_filters);
  d->winograd_buffer = upload_values(*device, p.filters.data, fp16, "the model's Winograd filters");
  return d;
}

}  // namespace

std::shared_ptr<const DeviceWeights> DeviceWeights::get(const std::shared_ptr<const FlowModel>& model,
                                                        const std::shared_ptr<VulkanDevice>& device, bool fp16,
                                                        bool winograd) {
  static std::mutex mutex;
  static std::map<std::tuple<const FlowModel*, const VulkanDevice*, bool, bool>, std::weak_ptr<const DeviceWeights>>
      uploaded;
  const std::lock_guard lock(mutex);
  auto& slot = uploaded[{model.get(), device.get(), fp16, winograd}];
  if (auto existing = slot.lock()) return existing;
  auto weights = upload(model, device, fp16, winograd);
  slot = weights;
  return weights;
}

}  // namespace neuflow::model::vulkan
