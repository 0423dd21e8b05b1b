// Everything trace.comp is given: the frame's constants, the scene's texel buffers and the
// pipeline's specialization constants (binding numbers in shared/types.h, texel layouts in
// shared/scene_layout.h).
#ifndef VKRAY_RESOURCES_GLSL
#define VKRAY_RESOURCES_GLSL

#include "shared/scene_layout.h"
#include "shared/types.h"

layout(std140, set = 0, binding = VKRAY_BINDING_FRAME) uniform Frame { FrameUniforms frame_block; };
layout(set = 0, binding = VKRAY_BINDING_PRIMITIVES) uniform samplerBuffer primitives;
layout(set = 0, binding = VKRAY_BINDING_NORMALS) uniform samplerBuffer normals;
layout(set = 0, binding = VKRAY_BINDING_NODES) uniform usamplerBuffer nodes;
layout(set = 0, binding = VKRAY_BINDING_MATERIALS) uniform samplerBuffer materials;
layout(set = 0, binding = VKRAY_BINDING_LIGHTS) uniform samplerBuffer lights;
layout(set = 0, binding = VKRAY_BINDING_EMITTERS) uniform samplerBuffer emitters;
layout(set = 0, binding = VKRAY_BINDING_TEXCOORDS) uniform samplerBuffer texcoords;
layout(set = 0, binding = VKRAY_BINDING_TEXTURES) uniform samplerBuffer textures;
layout(set = 0, binding = VKRAY_BINDING_TANGENTS) uniform samplerBuffer tangents;
layout(set = 0, binding = VKRAY_BINDING_COLOURS) uniform samplerBuffer colours;
layout(set = 0, binding = VKRAY_BINDING_INSTANCES) uniform samplerBuffer instances;
layout(set = 0, binding = VKRAY_BINDING_ENVIRONMENT) uniform samplerBuffer environment;
layout(set = 0, binding = VKRAY_BINDING_ENVIRONMENT_CDF) uniform samplerBuffer environment_cdf;

// The frame's constants as every function reads them: a private copy of the uniform block, made
// by load_frame() before anything else in main. llvmpipe reads a uniform block lane by lane at
// every use; a private copy is read like any variable (docs/design.md, "What the time goes to").
FrameUniforms frame;

void load_frame() { frame = frame_block; }

// Set per scene and render by the host (gpu::ShaderVariant), so that a pipeline has no code for
// what the render cannot need: on llvmpipe code behind an `if` costs every lane, masked, even when
// no lane takes it. Declared from the table in shared/types.h, which the host's pipeline reads too.
#define VKRAY_DECLARE_SPEC_CONSTANT(id, name, member, value) layout(constant_id = id) const bool name = value;
VKRAY_SPECIALIZATION_CONSTANTS(VKRAY_DECLARE_SPEC_CONSTANT)
#undef VKRAY_DECLARE_SPEC_CONSTANT
#define VKRAY_DECLARE_MATERIAL_CONSTANT(number, name, properties) \
  layout(constant_id = VKRAY_SPEC_MATERIALS + int(number)) const bool SCENE_HAS_##name = true;
VKRAY_MATERIAL_TYPES(VKRAY_DECLARE_MATERIAL_CONSTANT)
#undef VKRAY_DECLARE_MATERIAL_CONSTANT

#endif
