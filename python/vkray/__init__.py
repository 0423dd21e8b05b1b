"""vkray from Python: render scenes on any Vulkan device into numpy arrays.

A thin face on vkray's C++ library (the one the ``vkray`` command uses): the same scenes, the same
images, the same errors with the same messages.

    >>> import vkray
    >>> image = vkray.render("scenes/cornell.json", width=256, height=256)
    >>> image.shape, image.dtype
    ((256, 256, 3), dtype('float32'))

Scenes are scene files (``.json``, docs/scene-format.md) or dicts in the same format, where numpy
arrays may stand wherever the format has lists of numbers. Images are linear radiance, float32,
top row first, exactly what ``vkray render -o x.pfm`` writes.

``vkray.Renderer`` keeps the device, the compiled shaders, the mesh files and the last scene on the
device between renders, so that a loop that moves the camera or edits lights and materials uploads
only what changed. Rendering releases the GIL; Ctrl-C stops every render, on any thread, within a
fraction of a second, each raising KeyboardInterrupt. Arguments are checked as the command line
checks its options (UsageError); docs/python.md says how a program may end during a render, and how
processes made by fork() render.
"""

from __future__ import annotations

import json
import math
import operator
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, NoReturn, Optional, Union

try:
    import numpy as np
except ModuleNotFoundError as _missing:  # a venv, pyenv or conda Python without Debian's python3-numpy
    raise ModuleNotFoundError(f"vkray needs numpy, which {sys.executable} cannot import: install it for this Python: "
                              f"{sys.executable} -m pip install numpy", name="numpy") from _missing

from . import _vkray
from . import _denoise
from ._denoise import denoise
from ._vkray import DeviceError, Error, InternalError, SceneError, UsageError, __version__

__all__ = [
    "AOVS",
    "DeviceError",
    "Error",
    "InternalError",
    "Renderer",
    "SceneError",
    "UsageError",
    "bands",
    "denoise",
    "devices",
    "merge",
    "parity",
    "read_image",
    "render",
    "write_image",
    "__version__",
]

#: The first-hit passes a render can return beside the image (docs/rendering.md, "First-hit passes").
AOVS = ("albedo", "normal", "position", "depth", "object")

Scene = Union[str, "os.PathLike[str]", Mapping[str, Any]]
Region = Union[str, tuple[int, int, int, int]]
Image = np.ndarray
RenderOutput = Union[np.ndarray, dict[str, np.ndarray]]

# The name a scene dict goes by in messages; its relative paths resolve against its folder.
_DICT_NAME = "<scene dict>"


def _scene_data(scene: Mapping[str, Any], file: str) -> Any:
    """The scene dict as plain JSON data, or a SceneError naming the key path of the first value JSON
    cannot hold (NaN, infinity, a complex number, any other object), as the scene parser names a key."""

    def fail(path: str, what: str) -> NoReturn:
        raise SceneError(f"{file}: {path or 'top level'}: {what}")

    def cannot_hold(path: str, value: Any) -> NoReturn:
        fail(path, f"a Python {type(value).__name__} is not a value a scene can hold")

    def text(path: str, value: str) -> str:
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:
            fail(path, f"{value!r} is not valid Unicode text")
        return str(value)

    def finite(path: str, value: float) -> float:
        if not math.isfinite(value):
            fail(path, f"{value} is not a value a scene can hold (JSON has no NaN or infinity)")
        return float(value)

    def plain(value: Any, path: str, depth: int) -> Any:
        if isinstance(value, np.ndarray):
            if value.dtype.kind == "f" and not np.isfinite(value).all():  # one test for the whole array
                index = tuple(np.argwhere(~np.isfinite(value))[0])
                finite(path + "".join(f"/{i}" for i in index), float(value[index]))
            if value.dtype.kind in "biuf":
                return value.tolist()
            value = value.tolist()
        elif isinstance(value, np.generic):
            value = value.item()
        elif isinstance(value, os.PathLike):
            value = os.fsdecode(value)
        if value is None or isinstance(value, bool):
            return value
        if isinstance(value, str):
            return text(path, value)
        if isinstance(value, int):
            return int(value)
        if isinstance(value, float):
            return finite(path, value)
        if isinstance(value, (Mapping, list, tuple)) and depth >= _vkray._MAX_JSON_DEPTH:
            return {} if isinstance(value, Mapping) else []  # too deep: the scene parser refuses it, in its words
        if isinstance(value, Mapping):
            out = {}
            for key, item in value.items():
                if not isinstance(key, str):
                    fail(path, f"a key is text, not a {type(key).__name__} ({key!r})")
                out[text(path, key)] = plain(item, f"{path}/{key}", depth + 1)
            return out
        if isinstance(value, (list, tuple)):
            return [plain(item, f"{path}/{i}", depth + 1) for i, item in enumerate(value)]
        cannot_hold(path, value)

    return plain(scene, "", 0)


def _source(scene: Scene, base_dir: Optional[Union[str, "os.PathLike[str]"]],
            environment: Optional[Union[str, "os.PathLike[str]"]] = None) -> Any:
    map_file = None if environment is None else _path("environment", environment)
    if isinstance(scene, (str, os.PathLike)):
        if base_dir is not None:
            raise UsageError("base_dir is for scene dicts: a scene file's paths resolve against its own folder")
        return _vkray._SceneSource(_path("scene", scene), None, map_file)
    if isinstance(scene, Mapping):
        folder = Path(_path("base_dir", base_dir)) if base_dir is not None else Path.cwd()
        file = os.fspath(folder / _DICT_NAME)
        return _vkray._SceneSource(file, json.dumps(_scene_data(scene, file), allow_nan=False), map_file)
    raise UsageError(f"scene: expected a file name or a dict, got a {type(scene).__name__}")


def _path(name: str, value: Any) -> str:
    try:
        return os.fsdecode(value)
    except TypeError:
        raise UsageError(f"{name}: expected a file name, got {value!r}") from None


def _flag(name: str, value: Any) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise UsageError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def _pass_names(aovs: Union[str, Iterable[str]]) -> list[str]:
    if isinstance(aovs, str):
        names = [aovs]
    elif isinstance(aovs, Iterable) and not isinstance(aovs, (bytes, bytearray)):
        names = list(aovs)
    else:
        names = [aovs]
    if not all(isinstance(name, str) for name in names):
        raise UsageError(f"aovs: expected names of passes ({', '.join(AOVS)}), got {aovs!r}")
    return [n for name in names for n in name.split(",")]


def _region_text(region: Optional[Region]) -> Optional[str]:
    if region is None or isinstance(region, str):
        return region
    bounds = None
    if isinstance(region, (tuple, list)) or (isinstance(region, np.ndarray) and region.ndim == 1):
        # operator.index: whole numbers (numpy's too), never a float cut down to one, nor a bool.
        if len(region) == 4 and not any(isinstance(v, (bool, np.bool_)) for v in region):
            try:
                bounds = [operator.index(v) for v in region]
            except TypeError:
                pass
    if bounds is None:
        raise UsageError(f"a region is (x0, y0, x1, y1) or 'I/N', not {region!r}")
    if min(bounds) < 0:
        raise UsageError(f"region {region!r}: pixel bounds are not negative")
    return ",".join(map(str, bounds))


def _request(width: Optional[int], height: Optional[int], spp: Optional[int], seed: Optional[int],
             aovs: Union[str, Iterable[str]], region: Optional[Region], output: Any = None,
             exr_float: bool = False) -> Any:
    # The numbers are checked against the library's limits, as the command line checks its flags.
    return _vkray._Request(width, height, spp, seed, _pass_names(aovs), _region_text(region),
                           None if output is None else _path("output", output), _flag("exr_float", exr_float))


def read_image(file: Union[str, "os.PathLike[str]"]) -> dict[str, np.ndarray]:
    """A render's image file as numpy arrays: an .exr (its colour and the first-hit passes it holds)
    or a .pfm, as the dict ``render(..., aovs=...)`` returns ("color", then each pass).

    Raises:
        SceneError: the file cannot be read (the message says why).
        UsageError: a .png (8-bit display values, not radiance), another type, or a part of a render.
    """
    return _vkray._read_image(_path("file", file))[0]


def write_image(output: Union[str, "os.PathLike[str]"], image: RenderOutput, *, exr_float: bool = False) -> None:
    """Writes an image, (height, width, 3) floats, or a render's dict (its "color" and passes) as
    ``vkray render -o`` writes a render: .png (8-bit sRGB, clamped), .pfm, or .exr with the passes as
    layers (16-bit half floats for colour, albedo and normal; 32-bit with ``exr_float``). The file is
    written whole or not at all.

    Raises:
        UsageError: arrays of the wrong shape or type, passes or ``exr_float`` for a .png or .pfm.
        SceneError: the output cannot be written.
    """
    arrays = dict(image) if isinstance(image, Mapping) else {"color": image}
    _vkray._write_image(_path("output", output), arrays, _flag("exr_float", exr_float))


def _guided(aovs: Union[str, Iterable[str]], region: Optional[Region]) -> list[str]:
    """For a render with denoise=True: the passes asked for, then the denoiser's guides."""
    if region is not None:
        raise UsageError("denoise=True with a region: a denoiser looks across the region's edges; render the "
                         "regions, merge them (vkray.merge), then denoise the whole image (vkray.denoise)")
    _denoise._oidn()  # before the render, not after it
    names = _pass_names(aovs)
    return names + [g for g in _denoise.GUIDES if g not in names]


def _denoised(result: dict[str, np.ndarray], aovs: Union[str, Iterable[str]]) -> RenderOutput:
    """The render's colour denoised, with the passes asked for (as a render without denoise returns)."""
    image = _denoise.denoise(result["color"], *(result[g] for g in _denoise.GUIDES))
    asked = _pass_names(aovs)
    if not asked:
        return image
    return {"color": image, **{name: result[name] for name in asked if name != "color"}}


def _rendered(render_with: Any, width: Optional[int], height: Optional[int], spp: Optional[int], seed: Optional[int],
              aovs: Union[str, Iterable[str]], region: Optional[Region], denoise: bool) -> RenderOutput:
    """``render_with(request)``, a render of the GPU or the CPU reference; with ``denoise``, rendered
    with the guides too and returned denoised, as a render without it returns."""
    if not _flag("denoise", denoise):
        return render_with(_request(width, height, spp, seed, aovs, region))
    return _denoised(render_with(_request(width, height, spp, seed, _guided(aovs, region), region)), aovs)


class Renderer:
    """A Vulkan device kept open for any number of renders.

    It keeps the compiled shaders, the mesh files it read and the last scene it uploaded. A render of
    a scene whose geometry is the last one's (only the camera, lights, materials, background, image
    settings or integrator changed) re-uploads only the lights and materials, not the BVH or the
    primitives; ``last_stats`` says what a render cost and whether it reused the geometry.

    Args:
        device: an index or part of a name from ``vkray.devices()``; None picks the best device
            (a discrete GPU, then integrated, virtual, CPU).
        validate: run with the Khronos validation layer; any message it prints raises DeviceError.
        shader_dir: compile ``trace.comp`` from this folder instead of the installed shaders.

    Use it as a context manager, or call ``close()``, which also reports validation messages that
    arrive while the device is torn down.
    """

    def __init__(self, device: Optional[str] = None, *, validate: bool = False,
                 shader_dir: Optional[Union[str, "os.PathLike[str]"]] = None) -> None:
        self._renderer = _vkray._Renderer(None if device is None else str(device), _flag("validate", validate),
                                          None if shader_dir is None else _path("shader_dir", shader_dir))

    def render(self, scene: Scene, *, width: Optional[int] = None, height: Optional[int] = None,
               spp: Optional[int] = None, seed: Optional[int] = None, aovs: Union[str, Iterable[str]] = (),
               region: Optional[Region] = None,
               base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
               environment: Optional[Union[str, "os.PathLike[str]"]] = None, denoise: bool = False) -> RenderOutput:
        """Renders ``scene`` (see ``vkray.render``) on this renderer's device."""
        source = _source(scene, base_dir, environment)
        return _rendered(lambda request: self._renderer.render(source, request), width, height, spp, seed, aovs, region,
                         denoise)

    def render_to_file(self, scene: Scene, output: Union[str, "os.PathLike[str]"], *, width: Optional[int] = None,
                       height: Optional[int] = None, spp: Optional[int] = None, seed: Optional[int] = None,
                       aovs: Union[str, Iterable[str]] = (), region: Optional[Region] = None, exr_float: bool = False,
                       base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
                       environment: Optional[Union[str, "os.PathLike[str]"]] = None) -> None:
        """Renders ``scene`` and writes ``output`` (.png, .pfm or .exr) as ``vkray render -o`` does: the
        first-hit passes ``aovs`` as EXR layers, 32-bit channels with ``exr_float``, and a ``region``
        as a part for ``vkray.merge`` (.exr, or .pfm with its .pfm.json record). The file is written
        whole or not at all."""
        self._renderer.render(_source(scene, base_dir, environment),
                              _request(width, height, spp, seed, aovs, region, output, exr_float))

    @property
    def device(self) -> str:
        """The device in use, "name (driver)"; empty once closed."""
        return self._renderer.device

    @property
    def last_stats(self) -> Optional[dict[str, Any]]:
        """What the last render cost: seconds to load the scene, upload it (BVH build included) and
        trace it, rays traced, and whether the geometry already on the device was reused."""
        return self._renderer.last_stats

    def close(self) -> None:
        """Releases the device. Raises DeviceError when the validation layer reported anything."""
        self._renderer.close()

    def __enter__(self) -> "Renderer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def render(scene: Scene, *, width: Optional[int] = None, height: Optional[int] = None, spp: Optional[int] = None,
           seed: Optional[int] = None, renderer: str = "gpu", device: Optional[str] = None,
           aovs: Union[str, Iterable[str]] = (), region: Optional[Region] = None,
           base_dir: Optional[Union[str, "os.PathLike[str]"]] = None, threads: int = 0,
           environment: Optional[Union[str, "os.PathLike[str]"]] = None, denoise: bool = False) -> RenderOutput:
    """Renders a scene and returns linear radiance as a float32 array of shape (height, width, 3).

    Args:
        scene: a scene file name, or a dict in the scene format (numpy arrays allowed for lists of
            numbers); a dict's relative mesh paths resolve against ``base_dir`` (default: the
            current folder).
        width, height, spp, seed: override the scene's image settings and seed.
        renderer: "gpu" (the Vulkan compute shader) or "cpu" (the CPU reference, in double precision).
        device: for "gpu": an index or part of a name from ``vkray.devices()``.
        aovs: first-hit passes to return too, names from ``vkray.AOVS`` (or one comma-separated
            string). With any, the result is a dict: "color" and each pass; "albedo", "normal",
            "position" are (height, width, 3) float32, "depth" (height, width) float32 (infinite
            where nothing was hit), "object" (height, width) int32 (-1 where nothing was hit).
        region: only these pixels: (x0, y0, x1, y1), bounds in the full image (half-open), or "I/N",
            band I of N bands of about equal work (``vkray.bands``). Each pixel is the same as in the
            full render; the arrays hold the region alone.
        threads: for "cpu": threads to use, 1 to 256; 0, one per hardware thread.
        environment: an environment map (.hdr or .exr, equirectangular) that lights the scene in
            place of its own environment and background, as ``vkray render --environment`` does.
        denoise: denoise the image with Intel Open Image Denoise (``vkray.denoise``, which needs
            pyoidn), guided by the albedo and normal passes, rendered for it; not with a region.

    Raises:
        SceneError: the scene or a file it names cannot be used (the message names the file and key).
        UsageError: an argument is out of range or of the wrong kind (the message names it).
        DeviceError: no such device, or the device failed.
        KeyboardInterrupt: Ctrl-C, within a fraction of a second; also when an exception a signal
            handler raised on the main thread stopped the main thread's vkray call while this one
            ran (the library has one request to stop per process: docs/python.md).
    """
    if renderer == "gpu":
        with Renderer(device) as r:
            return r.render(scene, width=width, height=height, spp=spp, seed=seed, aovs=aovs, region=region,
                            base_dir=base_dir, environment=environment, denoise=denoise)
    if renderer == "cpu":
        if device is not None:
            raise UsageError("device is for renderer='gpu'; the CPU reference runs on the host")
        source = _source(scene, base_dir, environment)
        return _rendered(lambda request: _vkray.render_cpu(source, request, threads), width, height, spp, seed, aovs,
                         region, denoise)
    raise UsageError(f"renderer is 'gpu' or 'cpu', not {renderer!r}")


def parity(scene: Scene, *, width: Optional[int] = None, height: Optional[int] = None, spp: Optional[int] = None,
           seed: Optional[int] = None, device: Optional[str] = None,
           base_dir: Optional[Union[str, "os.PathLike[str]"]] = None, validate: bool = False,
           threads: int = 0, environment: Optional[Union[str, "os.PathLike[str]"]] = None) -> dict[str, Any]:
    """Renders ``scene`` on the device and with the CPU reference and compares the images and their
    first-hit passes, as ``vkray parity`` does. Returns the keys ``vkray parity --json`` prints;
    ``result["pass"]`` says whether they agree within the tolerance (``result["tolerance"]``)."""
    return json.loads(_vkray.parity(_source(scene, base_dir, environment), width, height, spp, seed,
                                    None if device is None else str(device), _flag("validate", validate), threads))


def bands(scene: Scene, count: int, *, width: Optional[int] = None, height: Optional[int] = None,
          base_dir: Optional[Union[str, "os.PathLike[str]"]] = None) -> list[tuple[int, int, int, int]]:
    """The ``count`` bands of whole rows, (x0, y0, x1, y1) from the top, that ``region="I/N"`` and
    ``vkray render --region I/N`` render: each about the same work, estimated by a small render of
    the scene with the CPU reference. Every process computes the same bands for the same scene."""
    return [tuple(b) for b in _vkray.bands(_source(scene, base_dir), count, width, height)]


def merge(output: Union[str, "os.PathLike[str]"], parts: Iterable[Union[str, "os.PathLike[str]"]]) -> dict[str, Any]:
    """Assembles the parts of a render (files written with a ``region``) into ``output``, as
    ``vkray merge`` does; raises SceneError when they are not the parts of one render or do not tile
    the image. Returns what was merged: parts, width, height, spp, seed, scene_digest,
    mixed_devices (parts of several devices agree within parity, not bit for bit) and
    passes_dropped (only an .exr output keeps first-hit passes)."""
    return _vkray.merge(_path("output", output), [_path("parts", p) for p in parts])


def devices() -> list[dict[str, Any]]:
    """Every Vulkan device the loader reports, as ``vkray devices`` lists them: index, name, type,
    driver, api_version, compute (whether it has a compute queue) and device_local_bytes."""
    return _vkray.devices()
