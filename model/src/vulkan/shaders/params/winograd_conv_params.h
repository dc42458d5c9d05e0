// winograd_conv (winograd_conv.comp) and winograd_conv_coopmat with its twin
// (winograd_conv_fragments.comp): a stride-1 3×3 convolution with padding 1 by F(4×4, 3×3) in
// one dispatch, with bias, addend and activation. The scalar kernel reads the OIHW filters from
// binding 0 (w_off) and transforms them as it loads them; the fragment kernels read them as
// transformed at upload (DeviceWeights), [36][filters_out][filters_in] fp16 with both sides
// padded with zeros to multiples of 16, so a fragment loads them straight from binding 4. Each
// kernel ignores the other's fields.
// The _parts variants (INPUT_IN_PARTS) read the input where a concatenation's parts lie instead
// of from the concatenated copy (winograd_tile_io.glsl): channels 0 .. part_c - 1 from binding 1
// at in_off, the rest from binding 5 at in2_off, each part stored (h >> shift) × (w >> shift)
// and read nearest-neighbour upsampled, through ReLU where relu_parts has its bit (1: the first
// part, 2: the second), then scaled. The others ignore these fields.
#ifndef NEUFLOW_SHADER_WINOGRAD_CONV_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_CONV_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(WinogradConvParams)
  int in_c, h, w, in_off;       // planar input (binding 1), channel 0 at in_off; the output is as large
  int out_c, out_off;           // planar output (binding 2), channel 0 at out_off
  int tiles_x, tiles;           // 4×4 output tiles per row, in all
  int w_off;                    // the OIHW filters in binding 0 (scalar kernel)
  int filters_off;              // the transformed filters in binding 4, a multiple of 16 (fragment kernels)
  int filters_in, filters_out;  // in_c and out_c rounded up to multiples of 16 (fragment kernels)
  int bias_off;                 // in binding 0 (the weights); < 0: none
  int add_off;                  // the addend (binding 3), shaped as the output; < 0: none
  int act;                      // one of activation.h's codes
  int part_c, in2_off;          // the input's parts (above)
  int shift, shift2;
  int relu_parts;
  float scale, scale2;
NEUFLOW_PUSH_CONSTANTS_END

#endif
