#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Attention without its score matrix (flash attention): 64 queries a workgroup, four
// invocations each holding a quarter of the query's and of the result's channels; the keys
// and values go through workgroup memory four tokens at a time, each score is the sum of the
// four partial dot products, and the softmax runs online (a running maximum and sum, the
// result rescaled when the maximum grows). Reads q, k and v once per workgroup; writes only
// the result. Workgroup row y takes queries from token y · query_step and keys and values from
// key_first + y · key_step (both frames' tokens in one tensor, each frame's queries against the
// other's keys: 2 rows); channels are `stride` values apart.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Q { VALUE q[]; };
layout(std430, binding = 1) readonly buffer K { VALUE k[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer V { VALUE v[]; };
#include "params/flash_attention_params.h"

const int QUERIES = 64, LANES = 4, KEYS = 4;
const int SLICE = kFlashAttentionMaxChannels / LANES;
const float LOWEST = -3.402823e38;
shared float k_tile[kFlashAttentionMaxChannels][KEYS];
shared float v_tile[kFlashAttentionMaxChannels][KEYS];
shared float partial[QUERIES][LANES][KEYS];

void main() {
  const int t = int(gl_LocalInvocationID.x);
  const int query = t / LANES, lane = t % LANES;
  const int n = p.tokens, stride = p.stride;
  const int frame = int(gl_WorkGroupID.y);
  const int q_base = p.q_off + frame * p.query_step, kv_first = frame * p.key_step + p.key_first;
  const int k_base = p.k_off + kv_first, v_base = p.v_off + kv_first;
  const int i = int(gl_WorkGroupID.x) * QUERIES + query;
  const bool in_range = i < n;
  const int q_slice = (p.dim + LANES - 1) / LANES, v_slice = (p.dv + LANES - 1) / LANES;
  const int q0 = lane * q_slice, v0 = lane * v_slice;
  const int q_count = clamp(p.dim - q0, 0, q_slice), v_count = clamp(p.dv - v0, 0, v_slice);

  float qv[SLICE], acc[SLICE];
  for (int c = 0; c < SLICE; ++c) {
    qv[c] = (in_range && c < q_count) ? p.alpha * float(q[q_base + (q0 + c) * stride + i]) : 0.0;
    acc[c] = 0.0;
  }
  float running_max = LOWEST, running_sum = 0.0;

  for (int j0 = 0; j0 < n; j0 += KEYS) {
    for (int e = t; e < p.dim * KEYS; e += 256) {
      const int d = e / KEYS, kk = e - d * KEYS, j = j0 + kk;
      k_tile[d][kk] = j < n ? float(k[k_base + d * stride + j]) : 0.0;
    }
    for (int e = t; e < p.dv * KEYS; e += 256) {
      const int d = e / KEYS, kk = e - d * KEYS, j = j0 + kk;
      v_tile[d][kk] = j < n ? float(v[v_base + d * stride + j]) : 0.0;
    }
    barrier();
    for (int kk = 0; kk < KEYS; ++kk) {
      float s = 0.0;
      for (int c = 0; c < q_count; ++c) s = fma(qv[c], k_tile[q0 + c][kk], s);
      partial[query][lane][kk] = s;
    }
    barrier();
    float score[KEYS];
    float block_max = running_max;
    for (int kk = 0; kk < KEYS; ++kk) {
      score[kk] = LOWEST;
      if (j0 + kk < n) {
        score[kk] = partial[query][0][kk] + partial[query][1][kk] + partial[query][2][kk] + partial[query][3][kk];
        block_max = max(block_max, score[kk]);
      }
    }
    const float rescale = exp(running_max - block_max);
    running_sum *= rescale;
    for (int c = 0; c < v_count; ++c) acc[c] *= rescale;
    for (int kk = 0; kk < KEYS; ++kk) {
      if (j0 + kk >= n) continue;
      const float w = exp(score[kk] - block_max);
      running_sum += w;
      for (int c = 0; c < v_count; ++c) acc[c] = fma(w, v_tile[v0 + c][kk], acc[c]);
    }
    running_max = block_max;
    barrier();  // the tiles are read; the next block may overwrite them
  }

  if (!in_range) return;
  const float inv = 1.0 / running_sum;
  for (int c = 0; c < v_count; ++c) {
    const int d = v0 + c;
    float r = acc[c] * inv;
    if (p.subtract_own_value != 0) r -= float(v[p.v_off + d * stride + frame * p.query_step + i]);
    dst[p.out_off + frame * p.query_step + d * stride + i] = VALUE(r);
  }
}
