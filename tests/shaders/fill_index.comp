// Test shader: writes base + global index into every element below count.
#version 460
layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push {
  uint count;
  uint base;
} pc;
layout(std430, binding = 0) writeonly buffer Out { uint data[]; };

void main() {
  uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  uint index = block * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (index < pc.count) data[index] = pc.base + index;
}
