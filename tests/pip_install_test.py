"""vkray installed as Python users install things: `pip install` from the source tree into a fresh
virtual environment (scikit-build-core over the CMake build, pyproject.toml), then used from outside
the source tree: the `vkray` command, the module, a farm job on two workers, each reading the shaders
and scenes the install put in the environment, and the denoiser (python/tests/test_denoise.py, run
again with the venv's pyoidn).

Run by CTest (tests/CMakeLists.txt) with VKRAY_SOURCE_DIR (the tree to install) and the test
driver's environment. The install builds vkray in a folder of its own, as pip does. pip fetches the
build requirements and the dependencies (scikit-build-core, pybind11, numpy, distributed, pyoidn,
and pytest to run the denoiser's tests) from PyPI,
or from whatever index pip is configured to use.
"""
import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import numpy as np
import pytest

SOURCE = Path(os.environ["VKRAY_SOURCE_DIR"])


def environment():
    """This environment without what points Python or vkray at the source tree or its build."""
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VKRAY_EXECUTABLE", "VKRAY_SCENE_DIR",
                                                            "VKRAY_SHADER_DIR", "PYTHONHOME")}


def run(args, cwd, timeout=600):
    done = subprocess.run([str(a) for a in args], cwd=cwd, env=environment(), capture_output=True, text=True,
                          timeout=timeout)
    assert done.returncode == 0, f"{' '.join(map(str, args))} exited {done.returncode}:\n{done.stdout}\n{done.stderr}"
    return done.stdout


def read_pfm(path):
    data = Path(path).read_bytes()
    header = data.split(b"\n", 3)
    assert header[0] == b"PF", path
    width, height = map(int, header[1].split())
    assert float(header[2]) < 0, "little-endian"
    pixels = np.frombuffer(header[3], dtype="<f4").reshape(height, width, 3)
    return pixels[::-1]  # PFM's bottom row comes first


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """A fresh venv with vkray[farm,denoise] installed from a copy of the source tree, which is then
    removed: what the install holds is all the tests below can use (the module knows the tree it was
    built from, and would fall back to its shaders and scenes)."""
    root = tmp_path_factory.mktemp("pip") / "venv"
    venv.EnvBuilder(with_pip=True).create(root)
    python = root / "bin" / "python"
    # Without a package index there is nothing to test: said as a skip (CTest shows "Skipped"), not a
    # failure, unless VKRAY_REQUIRE_PIP is set (.ci/run sets it). Anything else that goes wrong fails.
    probe = subprocess.run([str(python), "-m", "pip", "download", "--no-deps", "--retries", "3", "--timeout", "60",
                            "--dest", str(root.parent / "probe"), "scikit-build-core"], cwd=root.parent, env=environment(),
                           capture_output=True, text=True, timeout=600)
    if probe.returncode != 0:
        last = (probe.stderr.strip().splitlines() or ["(no message)"])[-1]
        if os.environ.get("VKRAY_REQUIRE_PIP"):  # in words that CTest's SKIP_REGULAR_EXPRESSION does not match
            pytest.fail(f"VKRAY_REQUIRE_PIP is set, and pip reaches no package index from this machine: {last}")
        pytest.skip(f"pip cannot reach its package index from this machine: {last}")
    source = root.parent / "source"
    shutil.copytree(SOURCE, source, ignore=shutil.ignore_patterns(".git", "build", "build-*", "__pycache__"))
    try:
        # Built without optimization, which takes two thirds of the time of pyproject.toml's release build:
        # this test is about what the install holds and where; the rest of the suite tests the
        # release build of the same sources. The timeout is less than CTest's TIMEOUT for this test,
        # so that a build that overstays is reported with pip's output.
        run([python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
             "--config-settings", "cmake.build-type=Debug", "--config-settings", "cmake.define.CMAKE_CXX_FLAGS_DEBUG=-O0",
             f"{source}[farm,denoise]", "pytest"], cwd=root.parent, timeout=2400)
    finally:
        shutil.rmtree(source)
    return root


def test_the_install_holds_the_command_the_module_and_their_data(env):
    python = env / "bin" / "python"
    where = run([python, "-c", "import vkray, importlib.metadata as m; "
                 "print(vkray.__file__); print(vkray.__version__); print(m.version('vkray'))"], cwd=env.parent).splitlines()
    assert Path(where[0]).is_relative_to(env), where[0]
    # One version: the command's, the module's, and the package's metadata (CMakeLists.txt's project()).
    assert run([env / "bin" / "vkray", "--version"], cwd=env.parent).strip() == "vkray " + where[1]
    assert where[1].split()[0] == where[2]
    for data in ("shaders/trace.comp", "scenes/cornell.json", "checks"):
        assert (env / "share" / "vkray" / data).exists(), data
    assert run([env / "bin" / "vkray-denoise", "--help"], cwd=env.parent).startswith("usage: vkray-denoise ")


def test_the_command_and_the_module_render_the_same_pixels(env, tmp_path):
    size = ["--width", "64", "--height", "48", "--spp", "2"]
    run([env / "bin" / "vkray", "render", "-q", *size, "-o", tmp_path / "command.pfm"], cwd=tmp_path)
    scene = env / "share" / "vkray" / "scenes" / "cornell.json"
    run([env / "bin" / "python", "-c", "import sys, numpy, vkray; "
         f"numpy.save(sys.argv[1], vkray.render({str(scene)!r}, width=64, height=48, spp=2))", tmp_path / "module.npy"],
        cwd=tmp_path)
    command = read_pfm(tmp_path / "command.pfm")
    module = np.load(tmp_path / "module.npy")
    assert module.shape == (48, 64, 3)
    assert np.array_equal(command, module)
    assert command.mean() > 0.01  # the Cornell box, not a black image


def test_a_farm_job_on_two_workers_gives_the_bytes_of_one_render(env, tmp_path):
    scene = env / "share" / "vkray" / "scenes" / "cornell-path.json"
    size = ["--width", "48", "--height", "32", "--spp", "2"]
    run([env / "bin" / "python", "-m", "vkray.farm", scene, "-o", tmp_path / "farm.pfm", "--workers", "2",
         "--regions", "4", "-q", *size], cwd=tmp_path)
    run([env / "bin" / "vkray", "render", scene, "-q", *size, "-o", tmp_path / "one.pfm"], cwd=tmp_path)
    assert (tmp_path / "farm.pfm").read_bytes() == (tmp_path / "one.pfm").read_bytes()


def test_the_denoiser_runs_with_the_installed_pyoidn(env, tmp_path):
    tests = SOURCE / "python" / "tests" / "test_denoise.py"
    done = subprocess.run([str(env / "bin" / "python"), "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", str(tests)],
                          cwd=tmp_path, env=dict(environment(), VKRAY_REQUIRE_OIDN="1"), capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "skipped" not in done.stdout, done.stdout
