// The built-in eye that tests and benchmarks use: a scene of the shape the
// talk's corneas have, written to glTF by `snell eye`.
#pragma once

#include "scene/scene.h"

#include <cstdint>

namespace snell::scene {

struct EyeOptions {
  float ior = 1.376f;           ///< the cornea's index of refraction (human cornea)
  float irisDepth = 0.0006f;    ///< metres from the limbus plane back to the iris
  float corneaBulge = 0.0025f;  ///< metres the cornea's apex stands in front of the limbus
  uint32_t resolution = 64;     ///< segments around each part; triangles grow with its square
  uint32_t crowd = 0;           ///< 0: one eye; N: N characters' eye pairs in a grid
  /// Adds the aqueous humour (IOR 1.336) behind the cornea as a closed volume
  /// of higher priority, so the cornea (a single sheet: everything behind it
  /// is cornea) hands over to it 0.55 mm in (nested dielectrics).
  bool aqueous = false;
};

/// Sclera; cornea as one mesh whose tip faces are transmissive (glTF
/// KHR_materials_transmission 1 and KHR_materials_ior) and whose other faces
/// are not (roughness 0.2: the catch lights' size); a shallow iris cone with
/// a procedural texture; a pupil; optionally the aqueous humour. Morph
/// targets "squash" and "dilate", a joint that turns each eye, a clip that
/// looks around and squashes, a camera and two lights. Metres, +Y up, the eye
/// looking down +Z.
Scene makeEye(const EyeOptions& options = {});

/// Throws std::invalid_argument naming the option that is out of range.
void checkEyeOptions(const EyeOptions& options);

}  // namespace snell::scene
