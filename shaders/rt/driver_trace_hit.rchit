#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_ray_tracing : require
#include "driver_hit.glsl"

layout(location = 0) rayPayloadInEXT DriverHit payload;
hitAttributeEXT vec2 bary;

void main() { payload = DriverHit(gl_HitTEXT, gl_InstanceCustomIndexEXT, gl_PrimitiveID, bary); }
