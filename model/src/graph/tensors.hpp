#pragma once
// The graph's tensors: a name, a logical [channels][height][width] shape (each backend picks
// its own layout) and where its memory comes from. Ops address channel ranges of them
// (Slice), which is how a concatenation costs nothing: its producers write into its slices.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace neuflow::model::graph {

using TensorId = int;

enum class Storage {
  transient,   // planned: shares memory with tensors whose live ranges it never meets
  persistent,  // memory of its own for the backend's life: it holds constant channels
  frame,       // a frame's features, which the backend keeps once per slot
};

// Which frame a frame tensor belongs to in a pass: an encode pass writes the frame it encodes;
// a flow pass reads the pair's two frames.
enum class FrameRole { encoded, first, second };

// Channels that no op writes: the backend fills them once (persistent and frame tensors).
enum class Fill {
  position_yx,   // (y - h/2, x - w/2): the 1/16 features' token positions
  grid_xy,       // (x, y): the global matching's pixel grid
  radius_plane,  // the correlation radius, the refinement's constant input
};
struct ConstantChannels {
  int first = 0, count = 0;
  Fill fill = Fill::radius_plane;
};

struct TensorDesc {
  std::string name;  // frame tensors: the same name in every role
  int c = 0, h = 0, w = 0;
  Storage storage = Storage::transient;
  FrameRole role = FrameRole::encoded;  // frame tensors only
  std::optional<ConstantChannels> constant;

  std::size_t plane() const { return static_cast<std::size_t>(h) * static_cast<std::size_t>(w); }
  std::size_t count() const { return static_cast<std::size_t>(c) * plane(); }
};

// The values of `t`'s constant channels, planar [count][h][w]; empty when it has none.
std::vector<float> constant_values(const TensorDesc& t);

// Channels [channel, channel + c) of a tensor.
struct Slice {
  TensorId tensor = -1;
  int channel = 0, c = 0;
  Slice channels(int first, int n) const { return {tensor, channel + first, n}; }
};

class TensorTable {
 public:
  TensorId add(TensorDesc desc) {
    tensors_.push_back(std::move(desc));
    return static_cast<TensorId>(tensors_.size() - 1);
  }
  // The whole tensor as a slice.
  Slice all(TensorId id) const { return {id, 0, at(id).c}; }
  // Whether `s` is all of its tensor's channels.
  bool whole(const Slice& s) const { return s.channel == 0 && s.c == at(s.tensor).c; }
  const TensorDesc& at(TensorId id) const { return tensors_.at(static_cast<std::size_t>(id)); }
  std::size_t size() const { return tensors_.size(); }
  const std::vector<TensorDesc>& descs() const { return tensors_; }

 private:
  std::vector<TensorDesc> tensors_;
};

}  // namespace neuflow::model::graph
