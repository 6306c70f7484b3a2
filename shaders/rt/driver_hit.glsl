// What the driver-rt pipeline's closest-hit shader hands the ray generation shader.
struct DriverHit {
  float t;
  uint instance;   // the top-level instance's custom index: snell's instance
  uint primitive;  // the triangle within its geometry
  vec2 bary;       // the driver's barycentrics: weights of v1 and v2
};
