// flash_attention (flash_attention.comp): out[:, i] = Σ_j softmax_j(alpha · q[:, i] · k[:, j]) v[:, j]
// over token lists [channels][tokens], less v[:, i] where subtract_own_value (the matching's
// flow: correspondence - grid); with two workgroup rows, each of two frames' tokens against the
// other's. dim and dv at most kFlashAttentionMaxChannels.
#ifndef NEUFLOW_SHADER_FLASH_ATTENTION_PARAMS_H
#define NEUFLOW_SHADER_FLASH_ATTENTION_PARAMS_H
#include "interface.h"

NEUFLOW_SHADER_CONST(kFlashAttentionMaxChannels, 192)

NEUFLOW_PUSH_CONSTANTS(FlashAttentionParams)
  int tokens, dim, dv;
  int q_off, k_off, v_off, out_off;  // q (binding 0), k (1), out (2), v (3)
  // Channels `stride` values apart; workgroup row y's queries from token y · query_step on, its
  // keys and values from key_first + y · key_step on (one row: stride = tokens, the rest 0).
  int stride, query_step, key_first, key_step;
  int subtract_own_value;
  float alpha;
NEUFLOW_PUSH_CONSTANTS_END

#endif
