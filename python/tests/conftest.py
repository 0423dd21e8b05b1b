"""What the Python tests share: where the source tree, the scenes and the built command are, and a
PFM reader of their own (not vkray's). CTest runs them with PYTHONPATH=build/python, lavapipe as the
Vulkan driver, and VKRAY_EXECUTABLE naming build/vkray (python/CMakeLists in the top CMakeLists)."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


@pytest.fixture
def scenes() -> Path:
    return SCENES


@pytest.fixture
def vkray_command() -> str:
    command = os.environ.get("VKRAY_EXECUTABLE")
    if not command:
        pytest.fail("VKRAY_EXECUTABLE is not set: run the Python tests through ctest")
    return command


def read_pfm(path: Path) -> np.ndarray:
    """A colour PFM as (height, width, 3) float32, top row first (the file stores the bottom row first)."""
    data = path.read_bytes()
    header, rest = data.split(b"\n", 3)[:3], data.split(b"\n", 3)[3]
    assert header[0] == b"PF"
    width, height = (int(v) for v in header[1].split())
    scale = float(header[2])
    dtype = "<f4" if scale < 0 else ">f4"
    pixels = np.frombuffer(rest, dtype=dtype, count=width * height * 3).reshape(height, width, 3)
    return np.ascontiguousarray(pixels[::-1]).astype(np.float32)


def run(*args: str, check: bool = True, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(list(args), check=check, capture_output=True, text=True, timeout=300, **kwargs)
