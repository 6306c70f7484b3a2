// Optics of shared/trace.h beyond the bend: Fresnel reflectance, the media a
// ray is inside (nested dielectrics), per-channel and textured IOR, the GGX
// highlight and the environment a reflected ray sees. Included by path.glsl;
// the including shader declares `materials`, `lights`, `environment` and `pc`.
#ifndef SNELL_OPTICS_GLSL
#define SNELL_OPTICS_GLSL

// Unpolarised dielectric reflectance for cosine c (> 0) and eta = n1 / n2; 1 past the critical angle.
float fresnelReflectance(float eta, float c) {
  float k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return 1.0;
  float ct = sqrt(k);
  float rs = (eta * c - ct) / (eta * c + ct);
  float rp = (eta * ct - c) / (eta * ct + c);
  return 0.5 * (rs * rs + rp * rp);
}

// KHR_materials_dispersion's spread around the base IOR; channel -1 (all) and 1 (green) keep it.
float channelIor(float ior, float dispersion, int channel) {
  if (channel < 0 || channel == 1 || dispersion <= 0.0) return ior;
  float spread = 0.025 * dispersion * (ior - 1.0);
  return channel == 0 ? ior - spread : ior + spread;
}

float mediumIor(uint material, int channel) {
  GpuMaterial m = materials[material];
  return channelIor(m.ior, m.dispersion, channel);
}

// The IOR of the material at a hit, its IOR texture's value there (read by
// the caller as bytes / 255) applied.
float surfaceIor(GpuMaterial m, float iorTexel, int channel) {
  float ior = m.ior;
  if (m.iorMap.texture != kNoTexture) ior = max(1.0, ior + m.iorOffset + m.iorScale * iorTexel);
  return channelIor(ior, m.dispersion, channel);
}

// ---------------------------------------------------------------- media

// The media the current path is inside, oldest first (globals, like the
// traversal stack: passing them by value made compilers copy them at every call).
uint media[kMaxMedia];
uint mediaCount;

float mediumPriority(uint material) { return materials[material].priority; }

// The entry that decides the medium: highest priority, ties to the latest; -1 in air.
int currentMedium() {
  int best = -1;
  for (uint i = 0u; i < mediaCount; ++i) {
    if (best < 0 || mediumPriority(media[i]) >= mediumPriority(media[best])) best = int(i);
  }
  return best;
}

void enterMedium(uint material) {
  if (mediaCount == kMaxMedia) {  // full: the oldest entry goes
    for (uint i = 1u; i < kMaxMedia; ++i) media[i - 1u] = media[i];
    --mediaCount;
  }
  media[mediaCount++] = material;
}

// Removes the latest entry of `material`; returns its index, -1 if it was not there.
int leaveMedium(uint material) {
  int at = -1;
  for (uint i = 0u; i < mediaCount; ++i) {
    if (media[i] == material) at = int(i);
  }
  if (at < 0) return -1;
  for (uint i = uint(at) + 1u; i < mediaCount; ++i) media[i - 1u] = media[i];
  --mediaCount;
  return at;
}

// ------------------------------------------------------------ reflection

// Every light's GGX highlight on a boundary of normal n (on the viewer's side)
// seen along dir, with the boundary's eta for the Fresnel term.
vec3 highlight(vec3 position, vec3 n, vec3 dir, float roughness, float eta) {
  vec3 v = -dir;
  float a = max(roughness * roughness, kMinAlpha), a2 = a * a;
  float nv = max(dot(n, v), 1e-4);
  vec3 sum = vec3(0.0);
  uint count = max(pc.lightCount, 1u);
  for (uint i = 0u; i < count; ++i) {
    vec3 l, e;
    if (!lightAt(i, pc.lightCount, pc.forward.xyz, position, l, e)) continue;
    if (dot(n, l) <= 0.0) continue;
    vec3 h = normalize(l + v);
    float nh = dot(n, h), vh = dot(v, h);
    if (nh <= 0.0 || vh <= 0.0) continue;
    float dd = nh * nh * (a2 - 1.0) + 1.0;
    sum += e * (a2 / (kPi * dd * dd)) * fresnelReflectance(eta, vh) / (4.0 * nv);
  }
  return sum;
}

vec3 environmentTexel(int x, int y, int width, int height) {
  x = ((x % width) + width) % width;
  y = clamp(y, 0, height - 1);
  return environment[1 + y * width + x].rgb;
}

vec3 environmentColour(vec3 d) {
  if (!opticsOn(kOpticsEnvironmentMap)) {
    return d.y >= 0.0 ? mix(kStudioHorizon, kStudioZenith, d.y) : mix(kStudioHorizon, kStudioGround, min(1.0, -4.0 * d.y));
  }
  int width = int(environment[0].x), height = int(environment[0].y);
  float u = 0.5 + atan(d.x, -d.z) / (2.0 * kPi), v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  vec2 p = vec2(u * float(width), v * float(height)) - 0.5;
  vec2 base = floor(p), f = p - base;
  int x = int(base.x), y = int(base.y);
  vec3 top = mix(environmentTexel(x, y, width, height), environmentTexel(x + 1, y, width, height), f.x);
  vec3 bottom = mix(environmentTexel(x, y + 1, width, height), environmentTexel(x + 1, y + 1, width, height), f.x);
  return mix(top, bottom, f.y);
}

#endif
