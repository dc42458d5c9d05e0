#pragma once
// NeuFlow-V2 written once, as two op lists over one tensor table: a frame's encoding (the
// backbone and the upsampler's image features, kept per frame) and a pair's flow from two
// encoded frames. The convolutions are named as the architecture table names them, and the
// stage marks (StageEnd) carry the names the observer, the GPU timestamps and the benchmark use.
// See shared/docs/neuflow-v2-network.md for what each stage does.
#include <string>

#include "graph/ops.hpp"
#include "graph/tensors.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::model::graph {

template <typename T>
struct NetworkGraph {
  TensorTable tensors;
  OpList<T> encode;      // writes the encoded frame's frame tensors
  OpList<T> flow;        // reads the first and second frames' frame tensors
  TensorId output = -1;  // the flow at model resolution, [2][height][width]
  int op_ids = 0;        // the nodes' ids are 0 .. op_ids - 1
  int height = 0, width = 0;
};

// The iterations the Vulkan backend plans its memory with: two steps at each scale, so that a
// tensor every step of a scale reads (conv1's constant share, the step input) is live across the
// steps, as with any number of them; one step, as at 1/16 by default, would let its memory go to
// the step's later tensors. The flow ops of other iterations are checked against the plan. (The
// CPU still plans with the default iterations, and so refuses two steps at 1/16 from 320×256 on.)
inline constexpr Iterations kPlanIterations{2, 2};

// height, width: the model resolution, multiples of 16. score_block_rows: how many rows of the
// attention's and the matching's score matrices a backend holds at once (1 to H/16 · W/16).
// The tensor table depends on the size and the block only, never on the iterations, so a
// backend may plan its memory with one graph and run the flow ops of another.
template <typename T>
NetworkGraph<T> build_network_graph(const BasicNetworkWeights<T>& weights, int height, int width,
                                    const Iterations& iterations, int score_block_rows);

// Throws std::logic_error naming the op when a slice leaves its tensor, a layer's weights do
// not fit its input and output, or a layer differs from the architecture table.
template <typename T>
void check_shapes(const NetworkGraph<T>& graph);

// What an op is, for messages ("conv2d refine_s8.conv2").
template <typename T>
std::string describe(const Op<T>& op);

}  // namespace neuflow::model::graph
