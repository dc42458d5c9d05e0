// Shared by the element-wise shaders: 256 invocations per workgroup, a grid-stride loop so a
// dispatch of at most 65535 workgroups covers any size.
layout(local_size_x = 256) in;
#define FOR_EACH(i, count) \
  for (int i = int(gl_GlobalInvocationID.x); i < (count); i += int(gl_NumWorkGroups.x) * 256)
