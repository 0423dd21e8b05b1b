// Room for `more` elements at the end of a vector, grown geometrically as push_back would grow it.
// reserve(size() + more) allocates exactly that much, so a vector filled by many such calls (a glTF
// file's primitives, a scene's meshes) is copied whole at every call: quadratic in the scene.
#pragma once

#include <algorithm>
#include <cstddef>

namespace vkray {

template <class Vector>
void reserve_more(Vector& v, size_t more) {
  const size_t needed = v.size() + more;
  if (needed > v.capacity()) v.reserve(std::max(needed, 2 * v.capacity()));
}

}  // namespace vkray
