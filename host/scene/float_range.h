// What the GPU's 32-bit floats can carry of a whole scene, checked when it is read, so that both
// renderers refuse the same scenes (the CPU reference, in double, could render them) and every
// scene they take renders finitely on both (docs/limits.md, "Floats on the GPU"). Values that pass
// one key's own range can still fail together: a scene so small that the squared distances the
// shader computes are below the smallest normal float, lights of brightnesses no one scale of
// floats holds together, an area light too small for its sampling density to be a float.
#pragma once

#include "scene/scene.h"

namespace vkray {

// A scene with geometry reaches at least this far from the origin (Scene::extent): its epsilon is
// then at least 1e-14, and a point light lights only points more than epsilon away from it, so the
// squared distances the shader divides by are at least 1e-28.
constexpr float kMinExtent = 1e-9f;

// The brightest radiance (an emission, the background, the ambient term, a light's intensity) is at
// most this many times the dimmest one that is not 0 (each taken by its brightest channel): the GPU
// scales them all by one power of two (gpu::radiance_exponent), which puts the brightest near 2^20 and
// the dimmest then 1e14 above the smallest normal float.
constexpr double kMaxRadianceRatio = 1e30;

// Throws SceneError naming the file and the key (or the material or light) for each of the above,
// and for an area light whose sampling density (its share of the lights' power over its area)
// passes the largest float.
void check_float_range(const Scene& scene);

}  // namespace vkray
