// The raster pass's depth pre-pass: visibility only, nothing shaded. The
// inputs match the vertex shader's outputs, which this stage leaves unread.
#version 460

layout(early_fragment_tests) in;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inUvs;
layout(location = 3) flat in vec3 inGeometricNormal;
layout(location = 4) flat in uint inMaterial;
layout(location = 5) flat in vec2 inDensity;
layout(location = 6) flat in vec3 inTangent;
layout(location = 7) flat in vec3 inBitangent;

void main() {}
