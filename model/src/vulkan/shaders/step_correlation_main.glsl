// main() of the refinement step's end beside its conv3 (STEP_CORRELATION): workgroups
// 0 .. p.conv_groups - 1 convolve (tile group g % p.tile_groups, channel group
// g / p.tile_groups: the hidden state), the rest take the correlation's blocks in turn (with
// STEP_UPDATE_ONLY, a scale's last step: the update's blocks).
// Which a workgroup does depends on its id alone, so its barriers stay in uniform control flow.
void main() {
  const int g = int(gl_WorkGroupID.x);
  if (g < p.conv_groups) {
    convolve(g % p.tile_groups, g / p.tile_groups);
    return;
  }
  const Correlation q = Correlation(p.h, p.w, p.channels, p.f0_off, p.f1_off, p.flow_off, p.corr_off, -1, 0,
                                    p.flow_copy_off, p.in_c, p.in_off, p.delta_w_off, p.delta_bias_off,
                                    p.resampled_off, p.factor, p.scale);
  const int id = int(gl_LocalInvocationIndex), plane = p.h * p.w;
  const int stride = (int(gl_NumWorkGroups.x) - p.conv_groups) * CORR_PIXELS;
  for (int block = (g - p.conv_groups) * CORR_PIXELS; block < plane; block += stride) {
#ifdef STEP_UPDATE_ONLY
    update_block(q, block, id % CORR_PIXELS, id / CORR_PIXELS);
#else
    correlate_block(q, block, id % CORR_PIXELS, id / CORR_PIXELS);
#endif
  }
}
