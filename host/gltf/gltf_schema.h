// A glTF document's values checked against the schema of glTF 2.0 and of the extensions vkray reads,
// before tinygltf reads them. tinygltf takes a value of the wrong kind for an absent one: a negative
// byteOffset reads as 0, a fractional or negative index as "none", an index past 2^31 wraps around,
// a string where a number belongs leaves the default, a bad element ends an integer array early, and
// a primitive it cannot parse is dropped from its mesh. Checked first, such a value is refused with
// its place in the document instead of being rendered as something the file did not say.
#pragma once

#include <filesystem>

#include <nlohmann/json_fwd.hpp>

namespace vkray {

// Checks every value tinygltf reads: an index (glTFid) names an element that exists; offsets,
// lengths, counts and strides are whole numbers in range; an enumeration holds one of its values;
// every other key has its JSON kind. Throws SceneError naming `file` and the first value that does
// not, by its place in the document ("accessors[3].byteOffset: expected ...").
void check_gltf_schema(const nlohmann::json& doc, const std::filesystem::path& file);

}  // namespace vkray
