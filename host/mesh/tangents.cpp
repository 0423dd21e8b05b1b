#include "mesh/tangents.h"

#include <new>

#include "mikktspace.h"

namespace vkray {
namespace {

struct Mesh {
  std::span<const TangentTriangle> triangles;
  std::vector<std::array<glm::vec4, 3>>* tangents;
};

const Mesh& mesh_of(const SMikkTSpaceContext* context) { return *static_cast<const Mesh*>(context->m_pUserData); }

int face_count(const SMikkTSpaceContext* context) { return int(mesh_of(context).triangles.size()); }
int corners_of_face(const SMikkTSpaceContext*, int) { return 3; }

void position(const SMikkTSpaceContext* context, float out[], int face, int corner) {
  const glm::vec3& p = mesh_of(context).triangles[size_t(face)].position[size_t(corner)];
  out[0] = p.x, out[1] = p.y, out[2] = p.z;
}

void normal(const SMikkTSpaceContext* context, float out[], int face, int corner) {
  const glm::vec3& n = mesh_of(context).triangles[size_t(face)].normal[size_t(corner)];
  out[0] = n.x, out[1] = n.y, out[2] = n.z;
}

void texcoord(const SMikkTSpaceContext* context, float out[], int face, int corner) {
  const glm::vec2& uv = mesh_of(context).triangles[size_t(face)].uv[size_t(corner)];
  out[0] = uv.x, out[1] = uv.y;
}

// MikkTSpace's bitangent, sign cross(normal, tangent), is the direction in which v grows; glTF's v
// runs down the picture while a normal map's green points up it, so glTF's sign is the opposite.
void set_tangent(const SMikkTSpaceContext* context, const float tangent[], float sign, int face, int corner) {
  (*mesh_of(context).tangents)[size_t(face)][size_t(corner)] = glm::vec4(tangent[0], tangent[1], tangent[2], sign < 0.0f ? 1.0f : -1.0f);
}

}  // namespace

std::vector<std::array<glm::vec4, 3>> mikktspace_tangents(std::span<const TangentTriangle> triangles) {
  std::vector<std::array<glm::vec4, 3>> tangents(triangles.size());
  if (triangles.empty()) return tangents;
  Mesh mesh{triangles, &tangents};
  SMikkTSpaceInterface callbacks{};
  callbacks.m_getNumFaces = face_count;
  callbacks.m_getNumVerticesOfFace = corners_of_face;
  callbacks.m_getPosition = position;
  callbacks.m_getNormal = normal;
  callbacks.m_getTexCoord = texcoord;
  callbacks.m_setTSpaceBasic = set_tangent;
  const SMikkTSpaceContext context{&callbacks, &mesh};
  if (!genTangSpaceDefault(&context)) throw std::bad_alloc();
  return tangents;
}

}  // namespace vkray
