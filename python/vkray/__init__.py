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
only what changed. Rendering releases the GIL; Ctrl-C stops a render within a fraction of a second
and raises KeyboardInterrupt.
"""

from __future__ import annotations

import json
import operator
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Optional, Union

try:
    import numpy as np
except ModuleNotFoundError as _missing:  # a venv, pyenv or conda Python without Debian's python3-numpy
    raise ModuleNotFoundError(f"vkray needs numpy, which {sys.executable} cannot import: install it for this Python: "
                              f"{sys.executable} -m pip install numpy", name="numpy") from _missing

from . import _vkray
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
    "devices",
    "merge",
    "parity",
    "render",
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


def _json_value(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"a {type(value).__name__} is not a value a scene can hold")


def _source(scene: Scene, base_dir: Optional[Union[str, "os.PathLike[str]"]]) -> Any:
    if isinstance(scene, (str, os.PathLike)):
        if base_dir is not None:
            raise UsageError("base_dir is for scene dicts: a scene file's paths resolve against its own folder")
        return _vkray._SceneSource(os.fspath(scene))
    if isinstance(scene, Mapping):
        folder = Path(base_dir) if base_dir is not None else Path.cwd()
        try:
            text = json.dumps(scene, default=_json_value, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise SceneError(f"{folder / _DICT_NAME}: {e}") from None
        return _vkray._SceneSource(os.fspath(folder / _DICT_NAME), text)
    raise UsageError(f"a scene is a file name or a dict, not a {type(scene).__name__}")


def _pass_names(aovs: Union[str, Iterable[str]]) -> list[str]:
    names = [aovs] if isinstance(aovs, str) else list(aovs)
    return [n for name in names for n in name.split(",")] if names else []


def _region_text(region: Optional[Region]) -> Optional[str]:
    if region is None or isinstance(region, str):
        return region
    try:
        # operator.index: whole numbers (numpy's too), never a float cut down to one.
        x0, y0, x1, y1 = (operator.index(v) for v in region)
    except (TypeError, ValueError):
        raise UsageError(f"a region is (x0, y0, x1, y1) or 'I/N', not {region!r}") from None
    if min(x0, y0, x1, y1) < 0:
        raise UsageError(f"region {region!r}: pixel bounds are not negative")
    return f"{x0},{y0},{x1},{y1}"


def _request(width: Optional[int], height: Optional[int], spp: Optional[int], seed: Optional[int],
             aovs: Union[str, Iterable[str]], region: Optional[Region], output: Any = None,
             exr_float: bool = False) -> Any:
    return _vkray._Request(width, height, spp, seed, _pass_names(aovs), _region_text(region),
                           None if output is None else os.fspath(output), exr_float)


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
        self._renderer = _vkray._Renderer(None if device is None else str(device), validate,
                                          None if shader_dir is None else os.fspath(shader_dir))

    def render(self, scene: Scene, *, width: Optional[int] = None, height: Optional[int] = None,
               spp: Optional[int] = None, seed: Optional[int] = None, aovs: Union[str, Iterable[str]] = (),
               region: Optional[Region] = None,
               base_dir: Optional[Union[str, "os.PathLike[str]"]] = None) -> RenderOutput:
        """Renders ``scene`` (see ``vkray.render``) on this renderer's device."""
        return self._renderer.render(_source(scene, base_dir), _request(width, height, spp, seed, aovs, region))

    def render_to_file(self, scene: Scene, output: Union[str, "os.PathLike[str]"], *, width: Optional[int] = None,
                       height: Optional[int] = None, spp: Optional[int] = None, seed: Optional[int] = None,
                       aovs: Union[str, Iterable[str]] = (), region: Optional[Region] = None, exr_float: bool = False,
                       base_dir: Optional[Union[str, "os.PathLike[str]"]] = None) -> None:
        """Renders ``scene`` and writes ``output`` (.png, .pfm or .exr) as ``vkray render -o`` does: the
        first-hit passes ``aovs`` as EXR layers, 32-bit channels with ``exr_float``, and a ``region``
        as a part for ``vkray.merge`` (.exr, or .pfm with its .pfm.json record). The file is written
        whole or not at all."""
        self._renderer.render(_source(scene, base_dir), _request(width, height, spp, seed, aovs, region, output, exr_float))

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
           base_dir: Optional[Union[str, "os.PathLike[str]"]] = None, threads: int = 0) -> RenderOutput:
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
        threads: for "cpu": threads to use; 0, one per hardware thread.

    Raises:
        SceneError: the scene or a file it names cannot be used (the message names the file and key).
        UsageError: an argument is out of range.
        DeviceError: no such device, or the device failed.
        KeyboardInterrupt: Ctrl-C, within a fraction of a second.
    """
    if renderer == "gpu":
        with Renderer(device) as r:
            return r.render(scene, width=width, height=height, spp=spp, seed=seed, aovs=aovs, region=region,
                            base_dir=base_dir)
    if renderer == "cpu":
        if device is not None:
            raise UsageError("device is for renderer='gpu'; the CPU reference runs on the host")
        return _vkray.render_cpu(_source(scene, base_dir), _request(width, height, spp, seed, aovs, region), threads)
    raise UsageError(f"renderer is 'gpu' or 'cpu', not {renderer!r}")


def parity(scene: Scene, *, width: Optional[int] = None, height: Optional[int] = None, spp: Optional[int] = None,
           seed: Optional[int] = None, device: Optional[str] = None,
           base_dir: Optional[Union[str, "os.PathLike[str]"]] = None, validate: bool = False,
           threads: int = 0) -> dict[str, Any]:
    """Renders ``scene`` on the device and with the CPU reference and compares the images and their
    first-hit passes, as ``vkray parity`` does. Returns the keys ``vkray parity --json`` prints;
    ``result["pass"]`` says whether they agree within the tolerance (``result["tolerance"]``)."""
    return json.loads(_vkray.parity(_source(scene, base_dir), width, height, spp, seed,
                                    None if device is None else str(device), validate, threads))


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
    return _vkray.merge(os.fspath(output), [os.fspath(p) for p in parts])


def devices() -> list[dict[str, Any]]:
    """Every Vulkan device the loader reports, as ``vkray devices`` lists them: index, name, type,
    driver, api_version, compute (whether it has a compute queue) and device_local_bytes."""
    return _vkray.devices()
