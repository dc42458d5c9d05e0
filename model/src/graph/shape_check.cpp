// The graph's own consistency: every slice inside its tensor, every layer's weights fitting the
// tensors it connects and matching the architecture table. A mistake in network_graph.cpp shows
// up here, named, before any backend records or runs it.
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "graph/network_graph.hpp"
#include "network_dims.hpp"
#include "neuflow/model/architecture.hpp"

namespace neuflow::model::graph {

template <typename T>
std::string describe(const Op<T>& op) {
  return std::visit(
      [](const auto& o) -> std::string {
        using O = std::decay_t<decltype(o)>;
        if constexpr (std::is_same_v<O, FrameInput>) return "frame input";
        if constexpr (std::is_same_v<O, AvgPool2x>) return "2x2 average pooling";
        if constexpr (std::is_same_v<O, Conv2d<T>>) return "conv2d " + o.layer;
        if constexpr (std::is_same_v<O, Linear<T>>) return "linear " + o.layer;
        if constexpr (std::is_same_v<O, Attention>) return "attention";
        if constexpr (std::is_same_v<O, LayerNorm<T>>) return "layer norm " + o.layer;
        if constexpr (std::is_same_v<O, ChannelAffine<T>>) return "channel affine " + o.layer;
        if constexpr (std::is_same_v<O, GlobalMatching>) return "global matching";
        if constexpr (std::is_same_v<O, Resample>) return "resample";
        if constexpr (std::is_same_v<O, Copy>) return "copy";
        if constexpr (std::is_same_v<O, CopyRows>) return "row copy";
        if constexpr (std::is_same_v<O, Zero>) return "zero";
        if constexpr (std::is_same_v<O, LocalCorrelation>) return "local correlation";
        if constexpr (std::is_same_v<O, RefineUpdate>) return "refinement update";
        if constexpr (std::is_same_v<O, ConvexUpsample>) return "convex upsampling";
        if constexpr (std::is_same_v<O, Output>) return "output";
        if constexpr (std::is_same_v<O, StageEnd>) return "stage end " + o.name;
      },
      op);
}

namespace {

template <typename T>
class Checker {
 public:
  explicit Checker(const NetworkGraph<T>& g) : g_(g) {}

  void check(const Op<T>& op) {
    op_ = &op;
    const Accesses a = accesses_of(op);
    for (const auto* slices : {&a.reads, &a.writes}) {
      for (const Slice& s : *slices) inside(s);
    }
    std::visit([&](const auto& o) { check_op(o); }, op);
  }

 private:
  void require(bool ok, const std::string& what) const {
    if (!ok) throw std::logic_error("the network graph's " + describe<T>(*op_) + ": " + what);
  }
  const TensorDesc& desc(const Slice& s) const { return g_.tensors.at(s.tensor); }
  void inside(const Slice& s) const {
    require(s.tensor >= 0 && static_cast<std::size_t>(s.tensor) < g_.tensors.size(), "a tensor that does not exist");
    require(s.channel >= 0 && s.c > 0 && s.channel + s.c <= desc(s).c,
            "channels " + std::to_string(s.channel) + "+" + std::to_string(s.c) + " of " + desc(s).name + " (" +
                std::to_string(desc(s).c) + " channels)");
  }
  bool same_plane(const Slice& a, const Slice& b) const { return desc(a).h == desc(b).h && desc(a).w == desc(b).w; }

  void check_op(const Conv2d<T>& o) {
    const BasicConvWeights<T>& w = *o.weights;
    require(o.in.c == w.in_channels && o.out.c == w.out_channels,
            "its weights take " + std::to_string(w.in_channels) + " channels to " + std::to_string(w.out_channels) +
                ", the graph gives " + std::to_string(o.in.c) + " to " + std::to_string(o.out.c));
    const auto out_size = [&](int in) { return (in + 2 * o.pad - w.kernel_h) / o.stride + 1; };
    require(out_size(desc(o.in).h) == desc(o.out).h && out_size(desc(o.in).w) == desc(o.out).w,
            "an output plane that does not follow from its input's, stride and padding");
    if (o.addend) require(o.addend->c == o.out.c && same_plane(*o.addend, o.out), "an addend shaped unlike its output");
    const LayerSpec& spec = neuflow_v2_layer(o.layer);  // std::out_of_range for a name the table lacks
    // The refinements' conv1 is split into the inputs that change every step and the fixed ones.
    const bool split = spec.in == kRefineInputChannels &&
                       (w.in_channels == kRefineDynamicChannels || w.in_channels == kRefineConstantChannels);
    require(spec.kind == LayerKind::conv && spec.out == w.out_channels && spec.kernel == w.kernel_h &&
                (spec.in == w.in_channels || split),
            "weights unlike the architecture table's layer");
  }
  void check_op(const Linear<T>& o) {
    require(o.in.c == o.weights->in_features && o.out.c == o.weights->out_features && same_plane(o.in, o.out),
            "weights that do not fit its tensors");
    // An attention layer's qkv_proj is the table's q_proj, k_proj and v_proj stacked.
    const std::string_view stacked = ".qkv_proj";
    std::vector<std::string> layers{o.layer};
    if (o.layer.ends_with(stacked)) {
      const std::string prefix = o.layer.substr(0, o.layer.size() - stacked.size());
      layers = {prefix + ".q_proj", prefix + ".k_proj", prefix + ".v_proj"};
    }
    int out = 0;
    for (const std::string& layer : layers) {
      const LayerSpec& spec = neuflow_v2_layer(layer);  // std::out_of_range for a name the table lacks
      require(spec.kind == LayerKind::linear && spec.in == o.in.c, "weights unlike the architecture table's layer");
      out += spec.out;
    }
    require(out == o.out.c, "weights unlike the architecture table's layer");
  }
  void check_op(const LayerNorm<T>& o) {
    require(o.in.c == o.out.c && same_plane(o.in, o.out), "an output shaped unlike its input");
    if (o.residual) require(o.residual->c == o.out.c && same_plane(*o.residual, o.out), "a residual unlike its output");
    require(neuflow_v2_layer(o.layer).out == o.in.c, "a width unlike the architecture table's layer");
  }
  void check_op(const ChannelAffine<T>& o) {
    require(neuflow_v2_layer(o.layer).out == o.inout.c, "a width unlike the architecture table's layer");
  }
  void check_op(const Attention& o) {
    require(
        o.q.c == o.k.c && o.v.c == o.out.c && same_plane(o.q, o.k) && same_plane(o.k, o.v) && same_plane(o.q, o.out),
        "queries, keys, values and output of different shapes");
    const std::size_t keys = desc(o.k).plane() / (o.across_frames ? 2 : 1);
    require(!o.across_frames || desc(o.k).h % 2 == 0, "two frames' tokens in an odd number of rows");
    require(desc({o.scores, 0, 1}).count() >= static_cast<std::size_t>(o.block_rows) * keys,
            "a score block smaller than its rows");
  }
  void check_op(const GlobalMatching& o) {
    require(o.f0.c == o.f1.c && same_plane(o.f0, o.f1) && o.grid.c == 2 && o.out.c == 2 && same_plane(o.f0, o.out),
            "features, grid and flow of different shapes");
    require(desc({o.scores, 0, 1}).count() >= static_cast<std::size_t>(o.block_rows) * desc(o.f1).plane(),
            "a score block smaller than its rows");
  }
  void check_op(const Resample& o) {
    require(o.in.c == o.out.c && desc(o.in).h * o.factor == desc(o.out).h && desc(o.in).w * o.factor == desc(o.out).w,
            "an output unlike its input times the factor");
  }
  void check_op(const AvgPool2x& o) {
    require(o.in.c == o.out.c && desc(o.in).h / 2 == desc(o.out).h && desc(o.in).w / 2 == desc(o.out).w,
            "an output unlike half its input");
  }
  void check_op(const Copy& o) {
    require(o.in.c == o.out.c && same_plane(o.in, o.out), "an output shaped unlike its input");
  }
  void check_op(const CopyRows& o) {
    require(o.in.c == o.out.c && desc(o.in).w == desc(o.out).w && o.rows > 0 && o.in_row >= 0 && o.out_row >= 0 &&
                o.in_row + o.rows <= desc(o.in).h && o.out_row + o.rows <= desc(o.out).h,
            "rows outside its tensors, or tensors of different widths");
  }
  void check_op(const LocalCorrelation& o) {
    require(o.f0.c == o.f1.c && o.flow.c == 2 && o.out.c == kCorrChannels && same_plane(o.f0, o.out) &&
                same_plane(o.f1, o.out) && same_plane(o.flow, o.out),
            "features, flow and window of different shapes");
  }
  void check_op(const RefineUpdate& o) {
    require(o.update.c == kRefineOutputChannels && o.hidden.c == kHiddenChannels && o.flow.c == 2 &&
                o.flow_copy.c == 2 && same_plane(o.update, o.flow),
            "an update unlike [delta, hidden]");
  }
  void check_op(const ConvexUpsample& o) {
    require(o.mask.c == kUpsampleMaskChannels && o.flow.c == 2 && o.out.c == 2 && same_plane(o.mask, o.flow) &&
                desc(o.flow).h * kUpsampleFactor == desc(o.out).h,
            "a mask, flow and output of different shapes");
  }
  void check_op(const FrameInput& o) { require(o.out.c == 3, "an input that is not three channels"); }
  void check_op(const Zero&) {}
  void check_op(const Output& o) { require(o.flow.c == 2, "an output that is not a flow"); }
  void check_op(const StageEnd&) {}

  const NetworkGraph<T>& g_;
  const Op<T>* op_ = nullptr;
};

}  // namespace

template <typename T>
void check_shapes(const NetworkGraph<T>& graph) {
  Checker<T> checker(graph);
  for (const auto* ops : {&graph.encode, &graph.flow}) {
    for (const Node<T>& node : *ops) checker.check(node.op);
  }
}

template void check_shapes(const NetworkGraph<std::vector<float>>&);
template void check_shapes(const NetworkGraph<PackedTensor>&);
template std::string describe(const Op<std::vector<float>>&);
template std::string describe(const Op<PackedTensor>&);

}  // namespace neuflow::model::graph
