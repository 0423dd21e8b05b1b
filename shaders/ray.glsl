// Ray and hit records used by every stage of the tracer.
#ifndef VKRAY_RAY_GLSL
#define VKRAY_RAY_GLSL

struct Ray {
  vec3 origin;
  vec3 dir;  // unit length (in world space; an instance's mesh space keeps its t, not its length)
};

const uint NO_HIT = 0xffffffffu;
const float FAR = 1e30;  // "no upper bound" for t; larger than any finite scene distance we accept

struct Hit {
  float t;
  uint prim;      // the primitive's slot in the primitive buffer (BVH leaf order); NO_HIT when nothing was hit
  uint instance;  // the entry of the instance it belongs to (instances.glsl); NO_INSTANCE for none
};

vec3 ray_at(Ray ray, float t) { return ray.origin + t * ray.dir; }

#endif
