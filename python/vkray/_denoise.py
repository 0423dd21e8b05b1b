"""Denoising with Intel Open Image Denoise (OIDN, through ``pyoidn`` from PyPI): ``vkray.denoise``.

A path-traced image at a few samples per pixel is noisy; OIDN's ``RT`` filter, a neural network
trained on rendered images, takes the noisy colour and, as guides, the albedo and normal of what each
pixel sees first: vkray's own first-hit passes. The inputs are prepared as OIDN documents them: the
colour as HDR linear radiance (not clamped; non-finite values and negative ones, which a correct
render does not have, count as black), the albedo in [0, 1] and the normals in [-1, 1].
"""

from __future__ import annotations

import os
import sys
import sysconfig
from collections.abc import Mapping
from typing import Any, Optional

import numpy as np

from ._vkray import DeviceError, UsageError

#: The qualities OIDN offers, fastest last.
QUALITIES = ("high", "balanced", "fast")

#: The first-hit passes that guide the denoiser, in the order denoise() takes them.
GUIDES = ("albedo", "normal")


def _image(name: str, value: Any, shape: Optional[tuple[int, ...]]) -> np.ndarray:
    """``value`` as a contiguous float32 (height, width, 3) array, or a UsageError naming ``name``."""
    if not isinstance(value, np.ndarray):
        try:
            value = np.asarray(value)
        except Exception as e:  # a ragged list, an object numpy cannot read
            raise UsageError(f"{name}: {e}") from None
    if value.dtype.kind != "f":
        raise UsageError(f"{name} is an array of {value.dtype}; vkray.denoise takes linear radiance as floats "
                         "(float16, float32 or float64), as vkray.render returns it")
    if value.ndim != 3 or value.shape[2] != 3 or value.shape[0] == 0 or value.shape[1] == 0:
        raise UsageError(f"{name} has shape {value.shape}; vkray.denoise takes (height, width, 3) arrays")
    if shape is not None and value.shape != shape:
        raise UsageError(f"{name} has shape {value.shape}, and color {shape}; the guides must be color's size")
    return np.ascontiguousarray(value, dtype=np.float32)


# pyoidn once it has loaded OIDN's library and opened its CPU device in this process.
_ready: Any = None


def _oidn(user: str = "vkray.denoise") -> Any:
    """pyoidn, with OIDN's library loaded and its CPU device opened once (12 ms), so that a denoiser
    that cannot run fails before a render, not after it. Raises ModuleNotFoundError saying that
    `user` needs pyoidn and how to install it for this Python, or DeviceError when OIDN cannot run."""
    global _ready
    if _ready is not None:
        return _ready
    try:
        import pyoidn
    except ModuleNotFoundError:
        system = sys.prefix == sys.base_prefix and os.path.exists(
            os.path.join(sysconfig.get_path("stdlib"), "EXTERNALLY-MANAGED"))
        if system:
            # Debian's /usr/bin/python3: pip does not add to the system's packages (PEP 668).
            advice = ("this Python's packages are the system's, to which pip does not add: install vkray with the "
                      "denoise extra into a venv, python3 -m venv ENV && ENV/bin/pip install '.[denoise]' in vkray's "
                      "source tree, and run ENV/bin/python (docs/python.md, Installing with pip)")
        else:
            advice = (f"install it for this Python: {sys.executable} -m pip install pyoidn (or pip install "
                      "'.[denoise]' in vkray's source tree)")
        raise ModuleNotFoundError(f"{user} needs Intel Open Image Denoise (pyoidn), which {sys.executable} "
                                  f"cannot import; {advice}", name="pyoidn") from None
    try:
        with pyoidn.Device() as device:
            device.commit()
            error = device.get_error()
    except (OSError, RuntimeError) as e:  # its library does not load
        raise DeviceError(f"Open Image Denoise (pyoidn, at {os.path.dirname(pyoidn.__file__)}) cannot run: {e}") from None
    if error:
        raise DeviceError(f"Open Image Denoise cannot open its CPU device: {error}")
    _ready = pyoidn
    return pyoidn


def denoise(color: Any, albedo: Any = None, normal: Any = None, *, quality: str = "high") -> np.ndarray:
    """Denoises a rendered image with Intel Open Image Denoise's ``RT`` filter.

    Args:
        color: linear radiance, (height, width, 3) floats, as ``vkray.render`` returns it; or the dict
            ``vkray.render(..., aovs=("albedo", "normal"))`` returns, whose "color", "albedo" and
            "normal" are used.
        albedo: the first-hit albedo pass (guides the filter to keep textures and edges); optional.
        normal: the first-hit normal pass (keeps geometric detail); only with albedo.
        quality: "high" (the default), "balanced" or "fast".

    Returns:
        The denoised image, float32 (height, width, 3).

    Raises:
        UsageError: an array of the wrong shape or type, normal without albedo, an unknown quality.
        ModuleNotFoundError: pyoidn is not installed for this Python (the message says how).
        DeviceError: OIDN failed.
    """
    if isinstance(color, Mapping):
        if albedo is not None or normal is not None:
            raise UsageError("color is a render's dict, which holds the guides: give albedo and normal in it, not beside it")
        if "color" not in color:
            raise UsageError(f"the render's dict has no 'color' (it has {', '.join(map(repr, color)) or 'nothing'})")
        color, albedo, normal = color["color"], color.get("albedo"), color.get("normal")
    if quality not in QUALITIES:
        raise UsageError(f"quality is {quality!r}; it is one of {', '.join(QUALITIES)}")
    c = _image("color", color, None)
    a = None if albedo is None else _image("albedo", albedo, c.shape)
    n = None if normal is None else _image("normal", normal, c.shape)
    if n is not None and a is None:
        raise UsageError("normal is given without albedo; OIDN takes the normal guide only beside the albedo")
    c = np.where(np.isfinite(c), np.maximum(c, 0.0), 0.0).astype(np.float32)
    if a is not None:
        a = np.clip(np.where(np.isfinite(a), a, 0.0), 0.0, 1.0).astype(np.float32)
    if n is not None:
        n = np.clip(np.where(np.isfinite(n), n, 0.0), -1.0, 1.0).astype(np.float32)
    oidn = _oidn()
    try:
        return np.asarray(oidn.denoise(c, albedo=a, normal=n, hdr=True, quality=quality), dtype=np.float32)
    except (OSError, RuntimeError) as e:
        raise DeviceError(f"Open Image Denoise: {e}") from None
