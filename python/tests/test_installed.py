"""The package as `cmake --install` lays it out: imported from the install, it renders with the
installed shaders, not the source tree's."""

import os
import subprocess
import sys
from pathlib import Path

import pytest


def test_the_installed_package_imports_and_renders_with_installed_shaders(tmp_path):
    build, cmake, site = (os.environ.get(k) for k in ("VKRAY_BUILD_DIR", "CMAKE_COMMAND", "VKRAY_PYTHON_INSTALL_DIR"))
    if not (build and cmake and site):
        pytest.fail("VKRAY_BUILD_DIR, CMAKE_COMMAND and VKRAY_PYTHON_INSTALL_DIR are set by ctest")
    prefix = tmp_path / "prefix"
    subprocess.run([cmake, "--install", build, "--prefix", str(prefix)], check=True, capture_output=True, timeout=120)
    env = dict(os.environ, PYTHONPATH=str(prefix / site))
    script = (
        "import sys, vkray\n"
        "print(vkray.__file__)\n"
        "print(vkray._vkray._shader_dir())\n"
        "image = vkray.render(sys.argv[1], width=32, height=32)\n"
        "print(image.shape, float(image.mean()) > 0)\n"
    )
    scene = prefix / "share" / "vkray" / "scenes" / "cornell.json"
    out = subprocess.run([sys.executable, "-c", script, str(scene)], env=env, cwd=tmp_path, check=True, capture_output=True,
                         text=True, timeout=120).stdout.splitlines()
    assert Path(out[0]).is_relative_to(prefix), out
    assert Path(out[1]) == prefix / "share" / "vkray" / "shaders", out
    assert out[2] == "(32, 32, 3) True"
