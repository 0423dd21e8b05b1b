"""Every shipped Khronos model's surfaces are where the glTF file says they are.

A reader written here, apart from vkray's (the JSON, the .glb chunks, buffers and data URIs,
accessors with strides, normalized integers and sparse substitutions, triangle lists, strips and
fans, morph targets at their default weights, the default scene's node hierarchy and
EXT_mesh_gpu_instancing), places every triangle of each model in world space. vkray renders the
model on the GPU (the CPU reference agrees with it: ShippedModelTest), with the first-hit position
and depth passes, and a ray cast here along each hit
pixel's own ray, from the camera through the point vkray hit, must meet the file's surfaces first
at that point: nothing of the file in front of it (a part vkray left out or misplaced), and a
surface of the file there (a part vkray added or placed where the file has none)."""

import base64
import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest

import vkray
from conftest import ROOT

MODELS = ROOT / "scenes" / "gltf"
COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
NORMALIZE = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}


class Gltf:
    """The geometry of a .gltf or .glb file, read with the specification open beside it."""

    def __init__(self, path: Path):
        data = path.read_bytes()
        self.binary = None
        if data[:4] == b"glTF":  # header, then a JSON chunk and perhaps a BIN chunk
            length, kind = struct.unpack_from("<II", data, 12)
            self.doc = json.loads(data[20:20 + length])
            if len(data) > 20 + length:
                bin_length, _ = struct.unpack_from("<II", data, 20 + length)
                self.binary = data[28 + length:28 + length + bin_length]
        else:
            self.doc = json.loads(data)
        self.folder = path.parent
        self.buffers = [self._buffer(b) for b in self.doc.get("buffers", [])]
        self.read = {}  # accessor -> its values, read once

    def _buffer(self, b: dict) -> bytes:
        uri = b.get("uri")
        if uri is None:
            return self.binary
        if uri.startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        return (self.folder / uri).read_bytes()

    def accessor(self, index: int) -> np.ndarray:
        if index not in self.read:
            self.read[index] = self._accessor(index)
        return self.read[index]

    def _accessor(self, index: int) -> np.ndarray:
        a = self.doc["accessors"][index]
        fmt, size = COMPONENTS[a["componentType"]]
        n, count = SIZES[a["type"]], a["count"]
        values = np.zeros((count, n))
        if "bufferView" in a:
            view = self.doc["bufferViews"][a["bufferView"]]
            data = self.buffers[view["buffer"]]
            start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
            stride = view.get("byteStride", size * n)
            values = np.ndarray((count, n), dtype="<" + fmt, buffer=data, offset=start, strides=(stride, size)).astype(float)
        if "sparse" in a:
            s = a["sparse"]
            ifmt, isize = COMPONENTS[s["indices"]["componentType"]]
            iview = self.doc["bufferViews"][s["indices"]["bufferView"]]
            vview = self.doc["bufferViews"][s["values"]["bufferView"]]
            for k in range(s["count"]):
                at = struct.unpack_from("<" + ifmt, self.buffers[iview["buffer"]],
                                        iview.get("byteOffset", 0) + s["indices"].get("byteOffset", 0) + k * isize)[0]
                values[at] = struct.unpack_from("<" + fmt * n, self.buffers[vview["buffer"]],
                                                vview.get("byteOffset", 0) + s["values"].get("byteOffset", 0) + k * size * n)
        if a.get("normalized") and a["componentType"] in NORMALIZE:
            values = np.maximum(values / NORMALIZE[a["componentType"]], -1.0)
        return values

    def local(self, node: dict) -> np.ndarray:
        if "matrix" in node:
            return np.array(node["matrix"], dtype=float).reshape(4, 4).T  # column-major
        t = np.eye(4)
        t[:3, 3] = node.get("translation", [0, 0, 0])
        return t @ rotation(node.get("rotation", [0, 0, 0, 1])) @ np.diag([*node.get("scale", [1, 1, 1]), 1.0])

    def triangles(self):
        """Every triangle the default scene places, in world space, (n, 3, 3); whether each is of an
        opaque material (alphaMode OPAQUE: nothing lets a ray through it); whether each is double-sided."""
        out, opaque, double_sided = [], [], []
        scene = self.doc["scenes"][self.doc.get("scene", 0)] if "scenes" in self.doc else None
        roots = scene["nodes"] if scene else [i for i in range(len(self.doc["nodes"]))
                                                if not any(i in n.get("children", []) for n in self.doc["nodes"])]
        stack = [(r, np.eye(4)) for r in roots]
        while stack:
            index, parent = stack.pop()
            node = self.doc["nodes"][index]
            world = parent @ self.local(node)
            if "mesh" in node:
                places = [world]
                gpu = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
                if gpu:
                    attributes = gpu["attributes"]
                    count = self.doc["accessors"][next(iter(attributes.values()))]["count"]
                    places = []
                    for i in range(count):
                        t = np.eye(4)
                        if "TRANSLATION" in attributes:
                            t[:3, 3] = self.accessor(attributes["TRANSLATION"])[i]
                        r = rotation(self.accessor(attributes["ROTATION"])[i]) if "ROTATION" in attributes else np.eye(4)
                        s = np.diag([*self.accessor(attributes["SCALE"])[i], 1.0]) if "SCALE" in attributes else np.eye(4)
                        places.append(world @ t @ r @ s)
                mesh = self.doc["meshes"][node["mesh"]]
                weights = node.get("weights", mesh.get("weights", []))
                for primitive in mesh["primitives"]:
                    local = self.primitive(primitive, weights)
                    material = self.doc["materials"][primitive["material"]] if "material" in primitive else {}
                    for place in places:
                        homogeneous = np.concatenate([local, np.ones(local.shape[:2] + (1,))], axis=2)
                        placed = (homogeneous @ place.T)[:, :, :3]
                        if np.linalg.det(place[:3, :3]) < 0:  # a mirror keeps front faces front (glTF 3.7.2.1)
                            placed = placed[:, [0, 2, 1]]
                        out.append(placed)
                        opaque.append(np.full(len(placed), material.get("alphaMode", "OPAQUE") == "OPAQUE"))
                        double_sided.append(np.full(len(placed), bool(material.get("doubleSided", False))))
            stack.extend((c, world) for c in node.get("children", []))
        if not out:
            return np.zeros((0, 3, 3)), np.zeros(0, bool), np.zeros(0, bool)
        return np.concatenate(out), np.concatenate(opaque), np.concatenate(double_sided)

    def primitive(self, p: dict, weights: list) -> np.ndarray:
        positions = self.accessor(p["attributes"]["POSITION"])
        for w, target in zip(weights, p.get("targets", [])):
            if w and "POSITION" in target:
                positions = positions + w * self.accessor(target["POSITION"])
        corners = self.accessor(p["indices"])[:, 0].astype(int) if "indices" in p else np.arange(len(positions))
        mode = p.get("mode", 4)
        if mode == 4:
            tris = corners[:len(corners) // 3 * 3].reshape(-1, 3)
        elif mode == 5:
            tris = np.array([[corners[i], corners[i + 1], corners[i + 2]] if i % 2 == 0 else
                             [corners[i + 1], corners[i], corners[i + 2]] for i in range(len(corners) - 2)])
        elif mode == 6:
            tris = np.array([[corners[i + 1], corners[i + 2], corners[0]] for i in range(len(corners) - 2)])
        else:
            return np.zeros((0, 3, 3))  # points and lines: no surface
        return positions[tris] if len(tris) else np.zeros((0, 3, 3))


def rotation(q) -> np.ndarray:
    x, y, z, w = q / np.linalg.norm(q)
    r = np.eye(4)
    r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return r


class Caster:
    """Rays from one eye through a size x size pinhole image (forward, right, up, focal in pixels),
    against every triangle: each triangle is listed in the pixels its projected box covers (all of
    them where it reaches behind the eye), so that a ray is tested against the triangles its pixel
    lists, by Moller and Trumbore's test in float64."""

    def __init__(self, eye, forward, right, up, focal, size, triangles, opaque, double_sided):
        self.eye, self.forward, self.right, self.up, self.focal, self.size = eye, forward, right, up, focal, size
        self.v0, self.e1, self.e2 = triangles[:, 0], triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
        self.normal = np.cross(self.e1, self.e2)
        self.opaque, self.double_sided = opaque, double_sided
        d = triangles - eye
        z = d @ forward
        behind = (z <= 1e-9 * np.abs(d).max()).any(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = (d @ right) / z * focal + size / 2
            y = size / 2 - (d @ up) / z * focal
        x0 = np.clip(np.floor(x.min(axis=1) - 1e-3), 0, size - 1).astype(int)
        x1 = np.clip(np.floor(x.max(axis=1) + 1e-3), 0, size - 1).astype(int)
        y0 = np.clip(np.floor(y.min(axis=1) - 1e-3), 0, size - 1).astype(int)
        y1 = np.clip(np.floor(y.max(axis=1) + 1e-3), 0, size - 1).astype(int)
        inside = ~behind & (x.max(axis=1) >= 0) & (x.min(axis=1) < size) & (y.max(axis=1) >= 0) & (y.min(axis=1) < size)
        self.everywhere = np.nonzero(behind)[0]
        index = np.nonzero(inside)[0]
        width, height = x1[index] - x0[index] + 1, y1[index] - y0[index] + 1
        count = width * height
        tri = np.repeat(index, count)
        k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        cell = (np.repeat(y0[index], count) + k // np.repeat(width, count)) * size + np.repeat(x0[index], count) + k % np.repeat(width, count)
        order = np.argsort(cell, kind="stable")
        self.cells = np.split(tri[order], np.searchsorted(cell[order], np.arange(1, size * size)))

    def pixel(self, direction):
        z = direction @ self.forward
        return (min(max(int((direction @ self.right) / z * self.focal + self.size / 2), 0), self.size - 1),
                min(max(int(self.size / 2 - (direction @ self.up) / z * self.focal), 0), self.size - 1))

    def cast(self, direction, distance, tolerance):
        """The nearest t > 0 at which a triangle stops a camera ray along the unit direction (an
        opaque one, met on a side it shows), and whether any triangle lies on it within tolerance of
        distance."""
        i, j = self.pixel(direction)
        c = np.concatenate([self.cells[j * self.size + i], self.everywhere])
        if len(c) == 0:
            return np.inf, False
        p = np.cross(direction, self.e2[c])
        det = np.einsum("tk,tk->t", p, self.e1[c])
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = self.eye - self.v0[c]
            u = np.einsum("tk,tk->t", p, s) * inv
            q = np.cross(s, self.e1[c])
            v = (q @ direction) * inv
            t = np.einsum("tk,tk->t", self.e2[c], q) * inv
        ok = (det != 0) & (u >= -1e-7) & (v >= -1e-7) & (u + v <= 1 + 1e-7) & (t > 0)
        shows = self.double_sided[c] | (self.normal[c] @ direction < 0)
        stops = ok & self.opaque[c] & shows
        return (t[stops].min() if stops.any() else np.inf), bool((ok & (np.abs(t - distance) <= tolerance)).any())


def model_files():
    for folder in sorted(p for p in MODELS.iterdir() if p.is_dir() and p.name != "LICENSES"):
        files = sorted(folder.rglob("*.gl[tb]*"))
        if files:
            yield pytest.param(files[0], id=folder.name)


@pytest.fixture(scope="module")
def renderer():
    with vkray.Renderer() as r:  # one device and one pipeline cache for every model
        yield r


@pytest.mark.parametrize("model", list(model_files()))
def test_surfaces_are_where_the_file_puts_them(model: Path, renderer):
    triangles, opaque, double_sided = Gltf(model).triangles()
    assert len(triangles) > 0
    lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    centre, radius = (lo + hi) / 2, max(np.linalg.norm(hi - lo) / 2, 1e-6)
    eye = centre + radius * 2.6 * np.array([0.3, 0.45, 1.0]) / np.linalg.norm([0.3, 0.45, 1.0])
    scene = {"camera": {"position": eye.tolist(), "look_at": centre.tolist(), "vertical_fov": 45},
             "lights": [{"type": "point", "position": eye.tolist(), "intensity": [1, 1, 1]}],
             "objects": [{"type": "gltf", "file": str(model)}]}
    size = 40
    out = renderer.render(scene, width=size, height=size, aovs=("position", "depth"))
    hit = np.isfinite(out["depth"])
    assert hit.sum() > 40, "the model should fill some of the view"
    tolerance = 1e-4 * (radius + np.linalg.norm(eye - centre))
    forward = (centre - eye) / np.linalg.norm(centre - eye)
    right = np.cross(forward, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    caster = Caster(eye, forward, right, up, 0.5 / math.tan(math.radians(45) / 2) * size, size, triangles, opaque, double_sided)
    # Where vkray hit: its point lies on a surface of the file, and nothing of the file that stops a
    # camera ray comes before it (a pixel whose ray grazes an edge may disagree, hence a few allowed).
    off_surface = in_front = 0
    for point in out["position"][hit].astype(np.float64):
        distance = np.linalg.norm(point - eye)
        nearest, on_surface = caster.cast((point - eye) / distance, distance, tolerance)
        off_surface += not on_surface
        in_front += nearest < distance - tolerance
    assert off_surface <= 0.02 * hit.sum(), f"{off_surface} of {hit.sum()} hits lie on no surface of the file"
    assert in_front <= 0.02 * hit.sum(), f"{in_front} of {hit.sum()} hits have a surface of the file in front of them"
    # Where vkray hit nothing: the ray through the pixel's centre (the pinhole of the scene contract,
    # shaders/camera.glsl) meets nothing of the file that stops it, but at the model's edges.
    shown = 0
    for j, i in zip(*np.nonzero(~hit)):
        through = (i + 0.5 - size / 2) * right + (size / 2 - (j + 0.5)) * up + caster.focal * forward
        shown += np.isfinite(caster.cast(through / np.linalg.norm(through), 0.0, 0.0)[0])
    assert shown <= 0.05 * hit.sum() + 2, f"{shown} pixels where vkray saw nothing show a surface of the file"
