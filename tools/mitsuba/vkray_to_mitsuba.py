#!/usr/bin/env python3
"""vkray scene JSON -> Mitsuba 3 scene dict, and a reference render with Mitsuba 3 (llvm_ad_rgb).

An independent renderer to compare vkray against. Needs the venv that tools/mitsuba/setup makes
(mitsuba 3.5.2, drjit 0.4.6, numpy; the llvm variant needs libLLVM, Debian 12: libllvm15).

  PY=$(tools/mitsuba/setup | tail -n1)
  $PY tools/mitsuba/vkray_to_mitsuba.py scenes/cornell.json                # print the dict
  $PY tools/mitsuba/vkray_to_mitsuba.py scenes/cornell.json --out /tmp/m.pfm --spp 64 \
      [--width W --height H] [--max-depth D] [--rr-depth R] [--threads T] [--seed S] [--time-runs K]

Rendering writes the image (.pfm: little-endian 'PF' RGB float32, rows bottom to top, as vkray
writes it; .exr through Mitsuba) and prints one JSON line with the timing. `seconds` is the wall
time of mi.render alone, after one warm-up render of the same scene that compiles the
kernels (it uses 4 or 5 samples per pixel: the kernels do not depend on the seed nor, beyond that,
on spp; `kernels_built_while_timed` checks it); with --time-runs K `seconds` is the minimum of K
renders, `seconds_median` their median. --max-depth on a scene without a path integrator renders
it as a path-traced scene; --rr-depth only applies to path tracing.

As a module: `scene_dict(path, overrides) -> (dict, info)`, with mitsuba's variant already set.

Mapping (vkray's docs/scene-format.md and docs/rendering.md):
  camera      look_at transform with the same up (Mitsuba's camera +X is left, image x grows to the
              right = normalize(f x up), as in vkray); fov_axis 'y', vertical_fov = 2 atan(0.5/f);
              aperture_radius > 0 -> 'thinlens'. Box pixel filter, hdrfilm rgb float32.
  materials   diffuse -> twosided(diffuse); mirror -> twosided(conductor, material 'none',
              specular_reflectance); glass -> dielectric(int_ior=ior, ext_ior=1);
              roughconductor -> twosided(roughconductor, distribution 'ggx', sample_visible, alpha
              or alpha_u/alpha_v, specular_reflectance, eta/k, else material 'none': Fresnel 1);
              roughdielectric -> roughdielectric(distribution 'ggx', sample_visible, alpha or alpha_u/alpha_v,
              int_ior (default 1.5, not Mitsuba's bk7), ext_ior 1). eta and k go in as 'srgb'
              with unbounded true (Mitsuba's dict reader refuses an 'rgb' value above 1).
              alpha_u runs along Mitsuba's dp/du (a sphere: around its world z axis, as vkray's
              tangent does; a mesh without UVs: coordinate_system(n), where vkray's tangent still
              runs around z), so anisotropic meshes agree only where the two tangents do;
              "emission" -> an 'area' emitter on each shape with the material (emits on the
              normal side). "normal_texture" -> 'normalmap' around the material's BSDF (inside
              twosided), its picture a raw (linear) 'bitmap', bilinear and repeating; Mitsuba's
              frame is its mesh's dp/du and n x dp/du, which is vkray's tangent frame wherever the
              texture is not mirrored. Mitsuba has no normal scale: normal_scale other than 1 is
              refused. Meshes of a normal-mapped material take their file's texture coordinates
              (Mitsuba's OBJ reader flips v as vkray's does). Alpha ("opacity", "opacity_texture",
              alpha_mode "blend") -> 'mask' around the BSDF, its opacity the factor or a raw
              bitmap of a greyscale picture, and the integrator 'volpath' (whose shadow rays pass
              masks as vkray's do; 'path' takes them as solid); alpha_mode "mask" converts only
              without a texture (whole, or a 'null' BSDF below the cutoff).
  objects     triangles/mesh are built in memory with the transform applied (M = T Rz Ry Rx S or
              the row-major matrix); flat shading = no vertex normals; "smooth": the file's
              normals, else area-weighted normals of the vertices welded by position (vkray's
              rule); flip_normals reverses the winding. Spheres: 'sphere' (its flip_normals).
  lights      point: intensity, or power / 4 pi; spot: intensity, cutoff_angle, beam_width, its to_world
              a look_at frame along its direction; directional: direction, irradiance.
  environment 'envmap' with the same to_world, given the map resampled 4x finer (environment_emitter
              says why); path integrator only.
  background  path: a 'constant' emitter. direct: composited where the camera ray misses (from
              the film's alpha), since vkray's direct model is not lit by the background.
  integrator  path -> 'path' (max_depth, rr_depth); direct or absent -> 'path' max_depth 2.
              ambient has no counterpart: ignored, with a warning.
"""
import argparse
import json
import math
import os
import pprint
import statistics
import sys
import time

import numpy as np

VARIANT = "llvm_ad_rgb"


def warn(msg):
    print(f"vkray_to_mitsuba: warning: {msg}", file=sys.stderr)


# ---- reading the scene ---------------------------------------------------------------------------

def strip_comments(text):
    """Removes // line and /* */ block comments outside strings (nlohmann::json's ignore_comments,
    which vkray's scene reader uses)."""
    out, i, n, in_string = [], 0, len(text), False
    while i < n:
        c = text[i]
        if in_string:
            out.append(c)
            if c == "\\" and i + 1 < n:
                out.append(text[i + 1])
                i += 1
            elif c == '"':
                in_string = False
        elif c == '"':
            in_string = True
            out.append(c)
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j  # keep the newline
            continue
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            if j < 0:
                raise ValueError("unterminated /* comment")
            out.append(" ")
            i = j + 2
            continue
        else:
            out.append(c)
        i += 1
    return "".join(out)


def load_scene_json(path):
    with open(path, encoding="utf-8") as f:
        return json.loads(strip_comments(f.read()))


def vec3(v, what):
    if not (isinstance(v, list) and len(v) == 3):
        raise ValueError(f"{what}: expected an array of 3 numbers, got {v!r}")
    return np.array(v, dtype=np.float64)


def rotation(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    m = np.eye(4)
    a, b = [(1, 2), (2, 0), (0, 1)][axis]  # the plane the rotation turns (right-handed)
    m[a, a], m[a, b], m[b, a], m[b, b] = c, -s, s, c
    return m


def transform_matrix(t):
    """vkray's object transform as a 4x4 (float64) matrix."""
    if t is None:
        return np.eye(4)
    if "matrix" in t:
        return np.array(t["matrix"], dtype=np.float64).reshape(4, 4)  # row-major
    translate = np.eye(4)
    translate[:3, 3] = t.get("translate", [0, 0, 0])
    ax, ay, az = t.get("rotate", [0, 0, 0])
    s = t.get("scale", 1.0)
    scale = np.diag(list(np.broadcast_to(np.asarray(s, dtype=np.float64), (3,))) + [1.0])
    return translate @ rotation(2, az) @ rotation(1, ay) @ rotation(0, ax) @ scale


def apply(m, points):
    return points @ m[:3, :3].T + m[:3, 3]


# ---- meshes --------------------------------------------------------------------------------------

def file_has_normals(path):
    """Whether a mesh file has its own normals for every face (vkray then uses them)."""
    if path.lower().endswith(".ply"):
        with open(path, "rb") as f:
            header = b""
            while not header.endswith(b"end_header\n") and not header.endswith(b"end_header\r\n"):
                line = f.readline()
                if not line:
                    break
                header += line
        return b"property float nx" in header or b"property double nx" in header or b"property float32 nx" in header
    has_vn, all_faces = False, True
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"vn"):
                has_vn = True
            elif line.startswith(b"f ") or line.startswith(b"f\t"):
                if any(corner.count(b"/") != 2 or corner.endswith(b"/") for corner in line.split()[1:]):
                    all_faces = False
    return has_vn and all_faces


def load_mesh_file(mi, path, with_normals):
    """Positions (V,3), faces (F,3), when asked the file's vertex normals, and its texture
    coordinates (V,2) if it has them, read by Mitsuba's own OBJ/PLY loader (independent of vkray's)."""
    kind = "ply" if path.lower().endswith(".ply") else "obj"
    mesh = mi.load_dict({"type": kind, "filename": path, "face_normals": not with_normals})
    params = mi.traverse(mesh)
    positions = np.array(params["vertex_positions"], dtype=np.float64).reshape(-1, 3)
    faces = np.array(params["faces"], dtype=np.int64).reshape(-1, 3)
    normals = np.array(params["vertex_normals"], dtype=np.float64).reshape(-1, 3) if with_normals else None
    texcoords = None
    if "vertex_texcoords" in params.keys() and len(params["vertex_texcoords"]) == 2 * len(positions):
        texcoords = np.array(params["vertex_texcoords"], dtype=np.float64).reshape(-1, 2)
    return positions, faces, normals, texcoords


def welded_area_normals(positions, faces):
    """Area-weighted vertex normals after welding vertices by position (vkray's rule)."""
    _, weld, = np.unique(positions, axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    p = positions[faces]
    face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])  # length = 2 * area
    acc = np.zeros((weld.max() + 1, 3))
    for k in range(3):
        np.add.at(acc, weld[faces[:, k]], face_n)
    n = acc[weld]
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.where(length > 0, length, 1), 0.0)


def make_mesh(mi, name, positions, faces, normals, props, texcoords=None):
    """An in-memory Mitsuba mesh; props carries its bsdf and emitter."""
    mesh = mi.Mesh(name, len(positions), len(faces), props, has_vertex_normals=normals is not None,
                   has_vertex_texcoords=texcoords is not None)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(positions.astype(np.float32).ravel())
    params["faces"] = mi.UInt32(faces.astype(np.uint32).ravel())
    if texcoords is not None:
        params["vertex_texcoords"] = mi.Float(texcoords.astype(np.float32).ravel())
    params.update()  # recomputes (angle-weighted) vertex normals ...
    if normals is not None:  # ... which are then replaced by ours
        params["vertex_normals"] = mi.Float(normals.astype(np.float32).ravel())
        params.update()
    return mesh


# ---- the conversion ------------------------------------------------------------------------------

def roughness(m, where):
    """A rough material's GGX roughness as Mitsuba's keys: alpha (default 0.1), or alpha_u and alpha_v."""
    if "alpha_u" in m or "alpha_v" in m:
        if "alpha" in m or "alpha_u" not in m or "alpha_v" not in m:
            raise ValueError(f"{where}: give either alpha or both alpha_u and alpha_v")
        return {"alpha_u": float(m["alpha_u"]), "alpha_v": float(m["alpha_v"])}
    return {"alpha": float(m.get("alpha", 0.1))}


def rough_conductor(m, where):
    """Mitsuba's roughconductor (one-sided: the caller wraps it in twosided) for a vkray material."""
    b = {"type": "roughconductor", "distribution": "ggx", "sample_visible": True,
         "specular_reflectance": {"type": "rgb", "value": m.get("specular_reflectance", [1.0, 1.0, 1.0])},
         **roughness(m, where)}
    if "eta" in m or "k" in m:
        # eta 0 and k 1 where not given, as in vkray and in Mitsuba. An 'rgb' dict is read as a
        # reflectance and refused above 1; 'srgb' with unbounded is how Mitsuba's own XML reader and
        # its material presets pass an index in RGB variants.
        for key, default in (("eta", 0.0), ("k", 1.0)):
            value = vec3(m[key], f"{where}/{key}") if key in m else [default] * 3
            b[key] = {"type": "srgb", "color": [float(x) for x in value], "unbounded": True}
    else:
        b["material"] = "none"
    return b


def alpha_mask(mi, m, b, base, where):
    """A material's alpha: 'blend' (the default where "opacity" or "opacity_texture" is given) is
    Mitsuba's 'mask' (each ray meets the surface with probability the opacity) around the BSDF, its
    opacity the factor, or a raw bitmap of a greyscale picture times the factor; 'mask' without a
    texture is whole or gone by its cutoff. A masked picture (glTF's MASK with a texture) has no
    counterpart, nor has a picture with colour or alpha (vkray reads its alpha, Mitsuba a bitmap's
    luminance): refused."""
    mode = m.get("alpha_mode", "blend")
    factor = float(m.get("opacity", 1.0))
    if mode == "opaque":
        return b
    if mode == "mask":
        if "opacity_texture" in m:
            raise ValueError(f"{where}/alpha_mode: Mitsuba has no alpha cutoff for a texture: only \"blend\" converts")
        return b if factor >= float(m.get("alpha_cutoff", 0.5)) else {"type": "null"}
    if "opacity_texture" in m:
        file = os.path.normpath(os.path.join(base, m["opacity_texture"]))
        if mi.Bitmap(file).pixel_format() != mi.Bitmap.PixelFormat.Y:
            raise ValueError(f"{where}/opacity_texture: {file}: only a greyscale picture without alpha converts "
                             "(vkray reads alpha where a picture has it, Mitsuba a bitmap's luminance)")
        opacity = {"type": "bitmap", "filename": file, "raw": True, "filter_type": "bilinear", "wrap_mode": "repeat"}
        if factor != 1.0:
            raise ValueError(f"{where}/opacity: Mitsuba's bitmap has no factor: with an opacity_texture, only 1 converts")
    else:
        if factor >= 1.0:
            return b
        opacity = factor
    return {"type": "mask", "opacity": opacity, "bsdf": b}


def environment_emitter(mi, env, base):
    """vkray's "environment" as Mitsuba's envmap, its to_world the same rotation.

    vkray's map is constant over each texel (u in [x, x+1) / W, theta in [y, y+1) / H pi); Mitsuba's
    envmap interpolates bilinearly between values it places at grid points (u = i / W, v = j / (H - 1)).
    So Mitsuba is given a map 4 times as fine, each of its grid points holding vkray's texel there:
    the two then differ only within a quarter texel of each texel's edge.
    """
    bitmap = mi.Bitmap(os.path.join(base, env["file"])).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    src = np.array(bitmap, dtype=np.float32)[:, :, :3] * float(env.get("scale", 1.0))
    h, w = src.shape[:2]
    k = 4
    cols = np.minimum((np.arange(k * w) / (k * w) * w).astype(np.int64), w - 1)
    rows = np.minimum((np.arange(k * h) / (k * h - 1) * h).astype(np.int64), h - 1)
    fine = np.ascontiguousarray(src[rows][:, cols])
    to_world = transform_matrix(env.get("transform", {}))
    return {"type": "envmap", "bitmap": mi.Bitmap(fine, mi.Bitmap.PixelFormat.RGB),
            "to_world": mi.ScalarTransform4f(to_world.tolist())}


def scene_dict(path, overrides=None):
    """(Mitsuba scene dict, info) for the vkray scene at `path`. Call mi.set_variant first."""
    import mitsuba as mi

    o = dict(overrides or {})
    scene = load_scene_json(path)
    base = os.path.dirname(os.path.abspath(path))
    known = {"description", "image", "camera", "integrator", "seed", "background", "environment", "ambient", "materials", "lights",
             "objects"}
    for key in scene:
        if key not in known:
            warn(f"{path}: /{key}: unknown key (ignored)")

    image = scene.get("image", {})
    width = o.get("width") or image.get("width", 512)
    height = o.get("height") or image.get("height", 512)
    spp = o.get("spp") or image.get("samples_per_pixel", 1)

    integ = scene.get("integrator", {"type": "direct"})
    # --max-depth turns a direct scene into a path-traced one (the background then lights it too).
    direct = integ.get("type", "direct") == "direct" and o.get("max_depth") is None
    max_depth = 2 if direct else integ.get("max_depth", -1)
    rr_depth = 5 if direct else integ.get("rr_depth", 5)
    if o.get("max_depth") is not None:
        max_depth = o["max_depth"]
    if o.get("rr_depth") is not None:
        rr_depth = o["rr_depth"]

    ambient = scene.get("ambient", [0, 0, 0])
    if any(a != 0 for a in ambient):
        warn(f"{path}: ambient {ambient} has no Mitsuba counterpart and is ignored"
             + (" (vkray's path integrator ignores it too)" if not direct else ""))
    background = np.array(scene.get("background", [0, 0, 0]), dtype=np.float64)
    composite_background = direct and background.any()

    d = {"type": "scene"}
    d["integrator"] = {"type": "path", "max_depth": int(max_depth), "rr_depth": int(rr_depth), "hide_emitters": False}

    # Extent of the scene (max |coordinate|), for the camera's clip planes.
    extent = [0.0]

    def grow(points):
        if len(points):
            extent[0] = max(extent[0], float(np.abs(points).max()))

    # camera
    cam = scene["camera"]
    position = vec3(cam["position"], "camera/position")
    grow(position[None])
    if "look_at" in cam:
        target = vec3(cam["look_at"], "camera/look_at")
    else:
        target = position + vec3(cam["direction"], "camera/direction")
    up = vec3(cam.get("up", [0, 1, 0]), "camera/up")
    if "vertical_fov" in cam:
        fov = float(cam["vertical_fov"])
    else:
        fov = math.degrees(2.0 * math.atan(0.5 / float(cam["focal_length"])))
    to_world = mi.ScalarTransform4f.look_at(origin=position.tolist(), target=target.tolist(), up=up.tolist())
    sensor = {"type": "perspective", "fov": fov, "fov_axis": "y", "to_world": to_world}
    aperture = float(cam.get("aperture_radius", 0.0))
    if aperture > 0:
        focus = cam.get("focus_distance")
        if focus is None:
            focus = float(np.linalg.norm(target - position))
        sensor.update(type="thinlens", aperture_radius=aperture, focus_distance=float(focus))
    sensor["film"] = {"type": "hdrfilm", "width": int(width), "height": int(height),
                      "pixel_format": "rgba" if composite_background else "rgb",
                      "component_format": "float32", "rfilter": {"type": "box"}}
    sensor["sampler"] = {"type": "independent", "sample_count": int(spp)}

    # materials
    bsdfs, emissions, specular, normal_mapped, see_through = {}, {}, False, set(), False
    for name, m in scene.get("materials", {}).items():
        kind = m.get("type", "diffuse")
        if kind == "diffuse":
            b = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["albedo"]}}}
        elif kind == "mirror":
            specular = True
            b = {"type": "twosided", "bsdf": {"type": "conductor", "material": "none",
                                              "specular_reflectance": {"type": "rgb", "value": m["reflectance"]}}}
        elif kind == "glass":
            specular = True
            b = {"type": "dielectric", "int_ior": float(m.get("ior", 1.5)), "ext_ior": 1.0}
        elif kind == "roughconductor":
            b = {"type": "twosided", "bsdf": rough_conductor(m, f"{path}: /materials/{name}")}
        elif kind == "roughdielectric":
            b = {"type": "roughdielectric", "distribution": "ggx", "sample_visible": True,
                 **roughness(m, f"{path}: /materials/{name}"), "int_ior": float(m.get("int_ior", 1.5)), "ext_ior": 1.0}
        else:
            raise ValueError(f"{path}: /materials/{name}/type: unknown material type {kind!r}")
        if "normal_texture" in m:
            if float(m.get("normal_scale", 1.0)) != 1.0:
                raise ValueError(f"{path}: /materials/{name}/normal_scale: Mitsuba's normalmap has no scale (only 1 converts)")
            normalmap = {"type": "bitmap", "filename": os.path.normpath(os.path.join(base, m["normal_texture"])), "raw": True,
                         "filter_type": "bilinear", "wrap_mode": "repeat"}
            if b["type"] == "twosided":
                b["bsdf"] = {"type": "normalmap", "normalmap": normalmap, "bsdf": b["bsdf"]}
            else:
                b = {"type": "normalmap", "normalmap": normalmap, "bsdf": b}
            normal_mapped.add(name)
        if "opacity" in m or "opacity_texture" in m:
            b = alpha_mask(mi, m, b, base, f"{path}: /materials/{name}")
            if b["type"] in ("mask", "null"):
                see_through = True
                if "opacity_texture" in m:
                    normal_mapped.add(name)  # (its meshes take their texture coordinates)
                e = m.get("emission")
                if e is not None and any(x != 0 for x in e):
                    raise ValueError(f"{path}: /materials/{name}: Mitsuba's area emitter ignores a mask's opacity "
                                     "(vkray's lamp sends light only where it is there): not converted")
        bsdfs[name] = mi.load_dict(b)  # one instance, shared by every shape with the material
        e = m.get("emission")
        if e is not None and any(x != 0 for x in e):
            emissions[name] = [float(x) for x in e]
    # Mitsuba's 'path' takes a mask as a solid surface on shadow rays; its 'volpath' passes them as
    # vkray does (and, as vkray, does not count the pass as a bounce).
    if see_through:
        d["integrator"]["type"] = "volpath"
    if direct and specular:
        warn("vkray's direct model follows mirrors and glass for several bounces; Mitsuba's path with "
             "max_depth 2 does not, so they will differ (use a path integrator to compare them)")

    def shape_props(material):
        props = mi.Properties()
        props["bsdf"] = bsdfs[material]
        if material in emissions:
            props["emitter"] = mi.load_dict({"type": "area", "radiance": {"type": "rgb", "value": emissions[material]}})
        return props

    # objects
    mesh_cache = {}
    n_emissive = 0
    for i, obj in enumerate(scene.get("objects", [])):
        kind = obj["type"]
        m = transform_matrix(obj.get("transform"))
        flip = bool(obj.get("flip_normals", False))
        material = obj["material"]
        n_emissive += material in emissions
        key = f"object{i}_{kind}"
        if kind == "sphere":
            center = apply(m, vec3(obj["center"], f"objects/{i}/center")[None])[0]
            radius = float(obj["radius"]) * float(np.linalg.norm(m[:3, 0]))
            grow(np.abs(center)[None] + radius)
            s = {"type": "sphere", "center": center.tolist(), "radius": radius, "flip_normals": flip,
                 "bsdf": bsdfs[material]}
            if material in emissions:
                s["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": emissions[material]}}
            d[key] = s
            continue
        if kind == "triangles":
            positions = apply(m, np.array(obj["positions"], dtype=np.float64).reshape(-1, 3))
            faces = np.array(obj["indices"], dtype=np.int64).reshape(-1, 3)
            normals = texcoords = None
        elif kind == "mesh":
            file = os.path.normpath(os.path.join(base, obj["file"]))
            smooth = bool(obj.get("smooth", False))
            if smooth and material in emissions:
                warn(f"objects/{i}: an emissive smooth mesh is given face normals (Mitsuba's area emitter "
                     "would emit on the side of the interpolated normal; vkray uses the geometric one)")
                smooth = False
            own = smooth and file_has_normals(file)
            if (file, own) not in mesh_cache:
                mesh_cache[(file, own)] = load_mesh_file(mi, file, own)
            positions, faces, normals, texcoords = mesh_cache[(file, own)]
            if material not in normal_mapped:
                texcoords = None
            positions = apply(m, positions)
            if smooth:
                if own:  # normals transform by the inverse transpose
                    normals = normals @ np.linalg.inv(m[:3, :3])
                    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
                else:
                    normals = welded_area_normals(positions, faces)
            else:
                normals = None
        else:
            raise ValueError(f"{path}: /objects/{i}/type: unknown object type {kind!r}")
        if flip:  # the other winding; the vertex normals turned with it
            faces = faces[:, [0, 2, 1]]
            if normals is not None:
                normals = -normals
        grow(positions)
        p = positions[faces]
        faces = faces[np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) > 0]  # vkray leaves zero-area triangles out
        if normals is not None:
            # vkray shades a triangle flat when a corner's normal is zero (or not finite): those go
            # into a second mesh without vertex normals.
            good = np.isfinite(normals).all(axis=1) & (np.linalg.norm(normals, axis=1) >= 0.5)
            flat = ~good[faces].all(axis=1)
            if flat.any():
                d[key + "_flat"] = make_mesh(mi, key + "_flat", positions, faces[flat], None, shape_props(material), texcoords)
                faces = faces[~flat]
        if len(faces):
            d[key] = make_mesh(mi, key, positions, faces, normals, shape_props(material), texcoords)

    # lights
    for i, light in enumerate(scene.get("lights", [])):
        kind = light.get("type")
        rgb = lambda key: {"type": "rgb", "value": [float(x) for x in light[key]]}
        if kind == "directional":
            direction = vec3(light["direction"], f"lights/{i}/direction")
            d[f"light{i}"] = {"type": "directional", "direction": (direction / np.linalg.norm(direction)).tolist(),
                              "irradiance": rgb("irradiance")}
            continue
        if kind not in ("point", "spot"):
            raise ValueError(f"{path}: /lights/{i}/type: unknown light type {kind!r}")
        p = vec3(light["position"], f"lights/{i}/position")
        grow(p[None])
        if kind == "spot":
            # Mitsuba's spot shines along its local +z: a look_at frame from the position toward the aim.
            aim = vec3(light["look_at"], f"lights/{i}/look_at") - p if "look_at" in light else vec3(light["direction"], f"lights/{i}/direction")
            aim = aim / np.linalg.norm(aim)
            up = np.array([0.0, 1.0, 0.0]) if abs(aim[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
            cutoff = float(light.get("cutoff_angle", 20.0))
            d[f"light{i}"] = {"type": "spot", "intensity": rgb("intensity"), "cutoff_angle": cutoff,
                              "beam_width": float(light.get("beam_width", 0.75 * cutoff)),
                              "to_world": mi.ScalarTransform4f.look_at(origin=p.tolist(), target=(p + aim).tolist(), up=up.tolist())}
            continue
        if "intensity" in light:
            intensity = np.array(light["intensity"], dtype=np.float64)
        else:
            intensity = np.array(light["power"], dtype=np.float64) / (4.0 * math.pi)
        d[f"light{i}"] = {"type": "point", "position": p.tolist(), "intensity": {"type": "rgb", "value": intensity.tolist()}}

    if background.any() and not direct:
        d["background"] = {"type": "constant", "radiance": {"type": "rgb", "value": background.tolist()}}
    if "environment" in scene:
        if direct:
            raise ValueError(f"{path}: /environment: vkray's direct model is lit by the map as one light; compare the "
                             "path integrator (give --max-depth)")
        d["environment"] = environment_emitter(mi, scene["environment"], base)

    # Mitsuba's default near clip (0.01) would cut geometry near the camera: vkray's epsilon is 1e-5 x extent.
    e = max(extent[0], 1e-30)
    sensor["near_clip"] = 1e-5 * e
    sensor["far_clip"] = 10.0 * e
    d["sensor"] = sensor

    info = {"scene": path, "width": int(width), "height": int(height), "spp": int(spp), "max_depth": int(max_depth),
            "rr_depth": int(rr_depth), "integrator": "direct" if direct else "path",
            "background_composited": [float(x) for x in background] if composite_background else None,
            "seed": int(scene.get("seed", 0)), "emissive_shapes": n_emissive}
    return d, info


# ---- images --------------------------------------------------------------------------------------

def write_pfm(path, rgb):
    """Little-endian 'PF' RGB float32, rows bottom to top (vkray's PFM)."""
    rgb = np.ascontiguousarray(np.asarray(rgb, dtype="<f4")[::-1, :, :3])
    h, w = rgb.shape[:2]
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode("ascii"))
        f.write(rgb.tobytes())


def write_image(mi, path, rgb):
    if path.lower().endswith(".pfm"):
        write_pfm(path, rgb)
    elif path.lower().endswith(".exr"):
        mi.Bitmap(np.ascontiguousarray(rgb, dtype=np.float32), mi.Bitmap.PixelFormat.RGB).write(path)
    else:
        raise ValueError(f"{path}: expected a .pfm or .exr output")


# ---- the command line ----------------------------------------------------------------------------

def printable(value):
    """The scene dict with Mitsuba's objects (meshes, BSDFs, transforms) as their own text: pprint
    cannot format them (their __repr__ is an unhashable pybind11 instancemethod)."""
    if isinstance(value, dict):
        return {k: printable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(printable(v) for v in value)
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    return " ".join(str(value).split())  # one line


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--out", help="render to this .pfm or .exr (without it: print the scene dict)")
    ap.add_argument("--spp", type=int)
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--max-depth", type=int)
    ap.add_argument("--rr-depth", type=int)
    ap.add_argument("--threads", type=int, help="drjit worker threads (default: one per core)")
    ap.add_argument("--seed", type=int, help="sampler seed (default: the scene's seed, else 0)")
    ap.add_argument("--time-runs", type=int, default=1, help="timed renders after the warm-up (report min and median)")
    a = ap.parse_args(argv)

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(VARIANT)
    mi.set_log_level(mi.LogLevel.Warn)
    if a.threads:
        dr.set_thread_count(a.threads)

    overrides = {"spp": a.spp, "width": a.width, "height": a.height, "max_depth": a.max_depth, "rr_depth": a.rr_depth}
    d, info = scene_dict(a.scene, overrides)
    if not a.out:
        pprint.pprint(printable(d), width=110)
        return 0

    scene = mi.load_dict(d)
    seed = a.seed if a.seed is not None else info["seed"]
    spp = info["spp"]

    def render(n):
        img = mi.render(scene, spp=n, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return img

    # Warm-up: traces and compiles the kernels. They depend on the film but not on the seed, nor on
    # spp beyond "a power of two or not" and "at least 4" (coalesced film writes), so a few samples do.
    warm_spp = spp if spp < 4 else (4 if spp & (spp - 1) == 0 else 5)
    t0 = time.perf_counter()
    render(warm_spp)
    warmup = time.perf_counter() - t0
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    dr.kernel_history()  # clears it
    times = []
    for _ in range(max(1, a.time_runs)):
        t0 = time.perf_counter()
        img = render(spp)
        times.append(time.perf_counter() - t0)
    # Kernels compiled (not found in drjit's memory or disk cache) during the timed renders: should be 0.
    built = sum(1 for k in dr.kernel_history() if k.get("cache_hit") == 0 and k.get("cache_disk") == 0)

    pixels = np.array(img, dtype=np.float32)
    rgb = pixels[:, :, :3]
    if info["background_composited"] is not None:  # misses show the background, which lights nothing
        rgb = rgb + (1.0 - pixels[:, :, 3:4]) * np.array(info["background_composited"], dtype=np.float32)
    write_image(mi, a.out, rgb)

    seconds = min(times)
    samples = info["width"] * info["height"] * spp
    out = {"scene": a.scene, "spp": spp, "width": info["width"], "height": info["height"],
           "integrator": info["integrator"], "max_depth": info["max_depth"], "rr_depth": info["rr_depth"],
           "threads": a.threads or os.cpu_count(), "seed": seed, "seconds": round(seconds, 6),
           "seconds_median": round(statistics.median(times), 6), "runs": len(times),
           "warmup_seconds": round(warmup, 6), "warmup_spp": warm_spp,
           "kernels_built_while_timed": built, "samples_per_second": round(samples / seconds, 1),
           "mitsuba": mi.__version__, "drjit": dr.__version__, "variant": mi.variant(), "out": a.out}
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    code = main()
    # mi.render leaves a few JIT variables referenced until exit (Mitsuba 3.5.2), which drjit reports
    # as leaks on shutdown; skip that noise.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
