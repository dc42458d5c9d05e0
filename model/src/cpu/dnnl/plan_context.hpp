#pragma once
// What the stages of one network plan are built with: the arena their buffers come from and
// how their convolutions are computed.
#include "dnnl/scratch_arena.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::model {

struct PlanContext {
  ScratchArena arena;
  CpuConvolution convolution = CpuConvolution::automatic;
};

}  // namespace neuflow::model
