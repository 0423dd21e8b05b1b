// A small scene compiled into the shader. What the tracer includes here when it walks the BVH is
// this file, which declares nothing. For a scene of a few dozen primitives the host serves code it
// generates under this name instead (host/packing/inline_scene.cpp): it defines VKRAY_INLINE_SCENE and
//   void test_inline_primitives(Ray ray, RayShear shear, float t_min, float t_max, bool any_hit,
//                               bool cull_back, float passed_t, uint passed_index, inout Hit hit)
// which tests every primitive of the scene in the scene's order, its coordinates written as
// constants, with shear_point and sheared_triangle (intersect.glsl) or intersect_sphere, and keeps
// the closest hit in (t_min, t_max) (with any_hit: a hit; with cull_back, a camera ray, not the back
// of a single-sided triangle; in a scene with see-through materials, after a surface passed,
// intersect_leaf's rule for passed_t and passed_index); traverse() (traversal.glsl) then calls it instead of walking the BVH.
