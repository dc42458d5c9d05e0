#pragma once
// The one tensor type passed between stages: a single image's activations in NHWC order
// (channels fastest), which is what token lists, correlation and per-pixel ops want.
// Convolution chains keep oneDNN's blocked layouts internally and convert at their ends.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace neuflow::model {

// A tensor's floats: its own, or a view of memory that outlives it (a CPU plan's arena, where
// the transient tensors of stages that never run at once share memory). A copy always owns
// its floats; a view stays a view when moved.
class TensorData {
 public:
  TensorData() = default;
  explicit TensorData(std::size_t n) : owned_(n, 0.f), ptr_(owned_.data()), size_(n) {}
  TensorData(const TensorData& other) : owned_(other.begin(), other.end()), ptr_(owned_.data()), size_(other.size_) {}
  TensorData(TensorData&& other) noexcept { take(std::move(other)); }
  TensorData& operator=(const TensorData& other) {
    if (this != &other) *this = TensorData(other);
    return *this;
  }
  TensorData& operator=(TensorData&& other) noexcept {
    if (this != &other) take(std::move(other));
    return *this;
  }

  // n zeros: in place where the size is already n (a view stays one), else in floats of its own.
  void assign_zeros(std::size_t n) {
    if (n == size_ && ptr_ != nullptr) {
      std::fill_n(ptr_, n, 0.f);
      return;
    }
    owned_.assign(n, 0.f);
    ptr_ = owned_.data();
    size_ = n;
    view_ = false;
  }
  // From now on the floats are memory[0, n), kept by someone else for as long as this is used.
  void view(float* memory, std::size_t n) {
    owned_.clear();
    owned_.shrink_to_fit();
    ptr_ = memory;
    size_ = n;
    view_ = true;
  }
  bool is_view() const { return view_; }

  float* data() { return ptr_; }
  const float* data() const { return ptr_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  float* begin() { return ptr_; }
  float* end() { return ptr_ + size_; }
  const float* begin() const { return ptr_; }
  const float* end() const { return ptr_ + size_; }
  float& operator[](std::size_t i) { return ptr_[i]; }
  const float& operator[](std::size_t i) const { return ptr_[i]; }

 private:
  void take(TensorData&& other) {
    view_ = other.view_;
    size_ = other.size_;
    if (view_) {
      owned_.clear();
      ptr_ = other.ptr_;
    } else {
      owned_ = std::move(other.owned_);
      ptr_ = owned_.data();
    }
    other.owned_.clear();
    other.ptr_ = nullptr;
    other.size_ = 0;
    other.view_ = false;
  }

  std::vector<float> owned_;
  float* ptr_ = nullptr;
  std::size_t size_ = 0;
  bool view_ = false;
};

struct Tensor {
  int h = 0;
  int w = 0;
  int c = 0;
  TensorData data;

  Tensor() = default;
  Tensor(int height, int width, int channels)
      : h(height), w(width), c(channels), data(static_cast<std::size_t>(height) * width * channels) {}

  // Zeros of this shape; a tensor whose floats are a view keeps them where the size is unchanged.
  void resize(int height, int width, int channels) {
    h = height;
    w = width;
    c = channels;
    data.assign_zeros(static_cast<std::size_t>(height) * width * channels);
  }
  std::size_t pixels() const { return static_cast<std::size_t>(h) * w; }
  float* pixel(int y, int x) { return data.data() + (static_cast<std::size_t>(y) * w + x) * c; }
  const float* pixel(int y, int x) const { return data.data() + (static_cast<std::size_t>(y) * w + x) * c; }
};

}  // namespace neuflow::model
