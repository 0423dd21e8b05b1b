// The BVH (host/bvh/bvh.h, 4-wide on the GPU) walked front to back for the closest hit (camera
// rays), or until any hit (shadow rays); or, for a scene compiled into the shader, every primitive
// tested in the scene's order.
#ifndef VKRAY_TRAVERSAL_GLSL
#define VKRAY_TRAVERSAL_GLSL

#include "instances.glsl"
#include "primitives.glsl"
#include "resources.glsl"

// Each step fetches everything it needs at once, before any math: on llvmpipe a texel fetch is a
// call that spills the caller's vector registers, and adjacent calls share one spill.

// Whether a camera ray that hits the triangle (a, b, c) meets the back of a single-sided one, and
// so passes through it (Material::double_sided): the side away from its winding's normal.
bool culled(Ray ray, vec4 a, vec4 b, vec4 c) {
  return (primitive_flags(a) & VKRAY_PRIM_SINGLE_SIDED) != 0u &&
         dot(ray.dir, triangle_normal_direction(a.xyz, b.xyz, c.xyz)) > 0.0;
}

// Tests the primitives of a leaf against the ray, keeping the closest hit (ties go to the primitive
// that comes first in the scene, VKRAY_TIE; hit_index is the best hit's place in the scene).
// instance, first_index: the instance the leaf belongs to and its first scene index (instances.glsl).
// Returns true when any_hit and something was hit. cull_back: the ray is a camera ray (culled()).
// passed_t, passed_index: a surface the ray has passed (trace()), after which the search goes on in
// the tie rule's order: a primitive that comes later in the scene counts from t_min, any other only
// past a tie with passed_t (a sphere's far side, say). passed_t 0: none.
bool intersect_leaf(Ray ray, RayShear shear, uint link, float t_min, float t_max, bool any_hit, bool cull_back, float passed_t,
                    uint passed_index, uint instance, uint first_index, inout Hit hit, inout uint hit_index) {
  uint first = leaf_first(link);
  uint end = first + leaf_count(link);
  // A do-while without `continue` (a leaf is never empty): see the light loop in shade.glsl.
  uint prim = first;
  do {
    int base = int(prim) * VKRAY_TEXELS_PER_PRIMITIVE;
    vec4 a = texelFetch(primitives, base), b = texelFetch(primitives, base + 1), c = texelFetch(primitives, base + 2);
    // Anything up to a tie with the best hit so far is still a candidate.
    float limit = hit.prim == NO_HIT ? t_max : hit.t * (1.0 + VKRAY_TIE);
    uint index = primitive_scene_index(b) + (SCENE_HAS_INSTANCES ? first_index : 0u);
    float t_from = SCENE_HAS_ALPHA && index <= passed_index ? max(t_min, passed_t * (1.0 + VKRAY_TIE)) : t_min;
    float t = intersect_primitive(ray, shear, a, b, c, t_from, limit);
    if (SCENE_HAS_SINGLE_SIDED && cull_back && t > 0.0 && culled(ray, a, b, c)) t = -1.0;
    if (t > 0.0) {
      if (any_hit) {
        hit = Hit(t, prim, instance);
        return true;
      }
      if (hit.prim == NO_HIT || t < hit.t * (1.0 - VKRAY_TIE) || index < hit_index) {
        hit = Hit(t, prim, instance);
        hit_index = index;
      }
    }
  } while (++prim < end);
  return false;
}

// ---- Small scenes, compiled into the shader (host/packing/inline_scene.h) ----------------------------------
// The generated test_inline_primitives() (contract in inline_scene.glsl) shears each distinct
// vertex once (shear_point) and tests each triangle with sheared_triangle (intersect.glsl), in the
// scene's order.

#include "inline_scene.glsl"

// Puts the pair with the smaller key first.
void order_pair(inout float key_a, inout uint link_a, inout float key_b, inout uint link_b) {
  bool swap = key_b < key_a;
  float key = key_a;
  uint link = link_a;
  key_a = swap ? key_b : key_a;
  link_a = swap ? link_b : link_a;
  key_b = swap ? key : key_b;
  link_b = swap ? link : link_b;
}

// The children of an inner node that the ray enters within (t_min, t_limit), nearest first: keys are
// the entry distances, NO_CHILD for a child not entered (those come last).
struct Children {
  vec4 key;
  uvec4 link;
};

const float NO_CHILD = 3.4e38;  // beyond any t (FAR)

// min and max as a compare and a select. The built-ins also define the result for a NaN operand,
// which costs llvmpipe a third instruction each; no slab-test value can be NaN (safe_inverse keeps
// 1 / d finite, and boxes and ray origins are finite).
vec4 min_no_nan(vec4 a, vec4 b) { return mix(a, b, lessThan(b, a)); }
vec4 max_no_nan(vec4 a, vec4 b) { return mix(a, b, greaterThan(b, a)); }

// A node's four texels, fetched together.
struct NodeTexels {
  uvec4 t[VKRAY_TEXELS_PER_NODE];
};

NodeTexels fetch_node(uint node) {
  int base = int(node) * VKRAY_TEXELS_PER_NODE;
  return NodeTexels(uvec4[VKRAY_TEXELS_PER_NODE](texelFetch(nodes, base), texelFetch(nodes, base + 1), texelFetch(nodes, base + 2),
                                                 texelFetch(nodes, base + 3)));
}

Children enter_node(Ray ray, vec3 inv_dir, bvec3 backward, NodeTexels texels, float t_min, float t_limit) {
  uvec4 header = texels.t[VKRAY_NODE_HEADER], links = texels.t[VKRAY_NODE_LINKS];
  NodeCorners corners = node_corners(texels.t[VKRAY_NODE_CORNERS], texels.t[VKRAY_NODE_CORNERS + 1]);
  // The four child boxes, one child per vector component.
  vec3 origin = uintBitsToFloat(header.xyz);
  vec3 scale = node_scale(header.w);
  vec4 lo_x = node_child_sides(origin.x, scale.x, corners.lo.x);
  vec4 lo_y = node_child_sides(origin.y, scale.y, corners.lo.y);
  vec4 lo_z = node_child_sides(origin.z, scale.z, corners.lo.z);
  vec4 hi_x = node_child_sides(origin.x, scale.x, corners.hi.x);
  vec4 hi_y = node_child_sides(origin.y, scale.y, corners.hi.y);
  vec4 hi_z = node_child_sides(origin.z, scale.z, corners.hi.z);
  // The slab test for four boxes at once: (t_enter, t_exit) clipped to (t_min, t_limit), a hit when
  // t_enter <= t_exit. t_exit is scaled by 1 + 2 gamma(3) (Ize, "Robust BVH Ray Traversal", JCGT
  // 2013) so float rounding can never reject a box the ray touches, flat boxes included (the box of
  // an axis-aligned wall has zero thickness).
  vec4 enter = max_no_nan(max_no_nan(((backward.x ? hi_x : lo_x) - ray.origin.x) * inv_dir.x,
                                     ((backward.y ? hi_y : lo_y) - ray.origin.y) * inv_dir.y),
                          max_no_nan(((backward.z ? hi_z : lo_z) - ray.origin.z) * inv_dir.z, vec4(t_min)));
  vec4 exit = min_no_nan(min_no_nan(((backward.x ? lo_x : hi_x) - ray.origin.x) * inv_dir.x,
                                    ((backward.y ? lo_y : hi_y) - ray.origin.y) * inv_dir.y),
                         min_no_nan(((backward.z ? lo_z : hi_z) - ray.origin.z) * inv_dir.z, vec4(t_limit))) *
              1.0000004;
  bvec4 entered = bvec4(uvec4(lessThanEqual(enter, exit)) & uvec4(notEqual(links, uvec4(0u))));
  vec4 key = mix(vec4(NO_CHILD), enter, entered);
  // Nearest first: a sorting network on four.
  float k0 = key.x, k1 = key.y, k2 = key.z, k3 = key.w;
  uint l0 = links.x, l1 = links.y, l2 = links.z, l3 = links.w;
  order_pair(k0, l0, k1, l1);
  order_pair(k2, l2, k3, l3);
  order_pair(k0, l0, k2, l2);
  order_pair(k1, l1, k3, l3);
  order_pair(k1, l1, k2, l2);
  return Children(vec4(k0, k1, k2, k3), uvec4(l0, l1, l2, l3));
}

// The nearest child of `c` next, the others onto the stack, farthest first; `pop` false when there
// is a child. A macro rather than a function: a stack passed to a function is copied in and out.
#define DESCEND(c, stack, depth, node, pop)  \
  if (c.key.x < NO_CHILD) {                   \
    stack[depth] = c.link.w;                  \
    depth += int(c.key.w < NO_CHILD);         \
    stack[depth] = c.link.z;                  \
    depth += int(c.key.z < NO_CHILD);         \
    stack[depth] = c.link.y;                  \
    depth += int(c.key.y < NO_CHILD);         \
    node = c.link.x;                          \
    pop = false;                              \
  }

// Walks one BVH from `root` with `ray` (in the space of its primitives; shear, inv_dir and backward
// made from it), keeping the closest hit in `hit` as intersect_leaf does. Returns true when any_hit
// and something was hit.
bool walk(Ray ray, RayShear shear, vec3 inv_dir, uint root, uint instance, uint first_index, float t_min, float t_max, bool any_hit,
          bool cull_back, float passed_t, uint passed_index, inout Hit hit, inout uint hit_index) {
  // The slab test's near plane on each axis is the box's low side when the ray goes up that axis.
  bvec3 backward = lessThan(inv_dir, vec3(0.0));
  // At most VKRAY_TRAVERSAL_STACK entries are in use; the spare ones keep a write at the top (one
  // past the last entry, by a lane whose result is masked off) inside the array.
  uint stack[VKRAY_TRAVERSAL_STACK + VKRAY_NODE_WIDTH];
  int depth = 0;
  uint node = root;
  // One loop step handles one node or one leaf: leaves are entered like nodes (nearest child next,
  // the others on the stack), so the leaf code exists once. On llvmpipe an `if` is not a branch
  // (both sides run, masked), so every step costs the leaf code plus the node code; 4-wide nodes
  // take fewer steps than binary ones (docs/design.md). For the same reason there is one pop
  // site for leaves and nodes alike: each site would cost every step a per-lane gather. A leaf popped
  // after a closer hit was found is still tested; the limit in intersect_leaf keeps the result exact.
  for (;;) {
    bool pop = true;
    if (is_leaf(node)) {
      if (intersect_leaf(ray, shear, node, t_min, t_max, any_hit, cull_back, passed_t, passed_index, instance, first_index, hit, hit_index))
        return true;
    } else {
      float t_limit = hit.prim == NO_HIT ? t_max : hit.t * (1.0 + VKRAY_TIE);
      Children c = enter_node(ray, inv_dir, backward, fetch_node(node), t_min, t_limit);
      DESCEND(c, stack, depth, node, pop);
    }
    if (pop) {
      if (depth == 0) break;
      node = stack[--depth];
    }
  }
  return false;
}

// Closest hit in (t_min, t_max), every surface taken as whole; with any_hit, the first hit found (for
// shadow rays). cull_back: a camera ray, which passes the back faces of single-sided triangles.
// passed_t, passed_index: intersect_leaf's.
Hit traverse(Ray ray, float t_min, float t_max, bool any_hit, bool cull_back, float passed_t, uint passed_index) {
  Hit hit = Hit(t_max, NO_HIT, NO_INSTANCE);
  uint hit_index = 0u;
  if (frame.primitive_count == 0u) return hit;
  RayShear shear = ray_shear(ray.dir);
#ifdef VKRAY_INLINE_SCENE
  test_inline_primitives(ray, shear, t_min, t_max, any_hit, SCENE_HAS_SINGLE_SIDED && cull_back, passed_t, passed_index, hit);
  return hit;
#endif
  vec3 inv_dir = safe_inverse(ray.dir);
  if (!SCENE_HAS_INSTANCES) {
    walk(ray, shear, inv_dir, 0u, NO_INSTANCE, 0u, t_min, t_max, any_hit, cull_back, passed_t, passed_index, hit, hit_index);
    return hit;
  }
  // Two levels: the top BVH, whose leaves are instance nodes (shared/scene_layout.h), one each; at
  // each, that instance's BVH walked with the ray in its space. Walked apart (a loop in a loop)
  // rather than as one loop, so that the instance's steps, most of the work, cost what they cost
  // in a scene without instances.
  bvec3 backward = lessThan(inv_dir, vec3(0.0));
  uint stack[VKRAY_TRAVERSAL_STACK + VKRAY_NODE_WIDTH];
  int depth = 0;
  uint node = 0u;
  for (;;) {
    bool pop = true;
    NodeTexels texels = fetch_node(is_leaf(node) ? leaf_first(node) : node);
    if (is_leaf(node)) {
      InstanceNode entry = instance_node(texels.t[0], texels.t[1], texels.t[2], texels.t[3]);
      Ray local = moved_ray(entry.row0, entry.row1, entry.row2, ray);
      if (walk(local, ray_shear(local.dir), safe_inverse(local.dir), entry.root, entry.instance, entry.first_index, t_min, t_max, any_hit,
               cull_back, passed_t, passed_index, hit, hit_index))
        return hit;
    } else {
      float t_limit = hit.prim == NO_HIT ? t_max : hit.t * (1.0 + VKRAY_TIE);
      Children c = enter_node(ray, inv_dir, backward, texels, t_min, t_limit);
      DESCEND(c, stack, depth, node, pop);
    }
    if (pop) {
      if (depth == 0) break;
      node = stack[--depth];
    }
  }
  return hit;
}

// The hit of a ray in (t_min, t_max) as traverse() finds it, where a see-through surface (alpha,
// shared/materials.h) lets the ray through where its opacity says so. In a scene with such surfaces
// the ray draws its alpha key from the stream (shared/sampling.h), and the search runs from the ray's
// start to the nearest surface, every surface taken as whole; where that surface lets the ray
// through, it runs again from there in the tie rule's order (VKRAY_TIE: a surface within a tie of
// the one passed counts if it comes later in the scene, so that a decal does not open the floor it
// lies on; a sphere's far side is the next surface), until a surface stops the ray or nothing is left. One opacity evaluation per surface the ray reaches, rather than
// one per primitive tested: on llvmpipe a lane pays for whatever code any lane beside it runs, and
// the opacity (a texture lookup) costs several times a triangle test. A shadow ray, too, looks for
// the nearest surface: one that is not the nearest could stand behind a surface that lets the ray
// through.
Hit trace(Ray ray, float t_min, float t_max, bool any_hit, bool cull_back, inout uint stream) {
  if (!SCENE_HAS_ALPHA) return traverse(ray, t_min, t_max, any_hit, cull_back, 0.0, 0u);
  uint key = next_word(stream);
  Hit hit;
  float from = t_min, passed_t = 0.0;
  uint passed_index = 0u;
  bool passes;
  do {  // (a do-while: see the sample loop in trace.comp)
    hit = traverse(ray, from, t_max, false, cull_back, passed_t, passed_index);
    // (The primitive's texels are read only for a hit: NO_HIT is no slot, and a read there would fall
    // outside the buffer, which a device without robust buffer access need not survive.)
    passes = hit.prim != NO_HIT && !meets_hit(ray, hit, key, passed_index);
    passed_t = hit.t;
    from = max(t_min, hit.t * (1.0 - VKRAY_TIE));
  } while (passes);
  return hit;
}

// The closest hit of a ray; camera_ray: the ray leaves the camera (single-sided back faces pass it).
Hit trace_closest(Ray ray, float t_min, float t_max, bool camera_ray, inout uint stream) {
  return trace(ray, t_min, t_max, false, camera_ray, stream);
}

// Whether anything lies on the ray in (t_min, t_max).
bool trace_any(Ray ray, float t_min, float t_max, inout uint stream) { return trace(ray, t_min, t_max, true, false, stream).prim != NO_HIT; }

#endif
