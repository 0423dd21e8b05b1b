"""vkray.denoise and render(..., denoise=True): Intel Open Image Denoise (pyoidn) fed vkray's own
first-hit passes as guides.

The checks of the arguments and of a missing pyoidn run wherever the tests run. Denoising itself needs
pyoidn, which Debian does not package: tests/pip_install_test.py runs this file again in a venv where
pip installed vkray[denoise], with VKRAY_REQUIRE_OIDN=1, where a missing pyoidn fails those tests."""

import importlib.util
import os
import signal
import subprocess
import sys
import time
import types

import numpy as np
import pytest

import vkray
from vkray import _denoise

HAVE_OIDN = importlib.util.find_spec("pyoidn") is not None or bool(os.environ.get("VKRAY_REQUIRE_OIDN"))
needs_oidn = pytest.mark.skipif(not HAVE_OIDN, reason="pyoidn is not installed for this Python; "
                                "tests/pip_install_test.py runs these in a venv that has it")

IMAGE = np.full((6, 8, 3), 0.5, np.float32)


@pytest.fixture(autouse=True)
def oidn_not_yet_opened(monkeypatch):
    """Each test finds pyoidn as it sets it up: vkray opens OIDN once per process and keeps it."""
    monkeypatch.setattr(_denoise, "_ready", None)


class UnloadablePyoidn(types.ModuleType):
    """A pyoidn whose OIDN library does not load (pyoidn loads it when a device is first made)."""

    def __init__(self):
        super().__init__("pyoidn")
        self.__file__ = "/nowhere/pyoidn/__init__.py"

    class Device:
        def __init__(self):
            raise OSError("cannot load library 'libOpenImageDenoise.so.2': no such file")


@pytest.mark.parametrize("args, kwargs, says", [
    ((np.zeros((6, 8, 3), np.uint8),), {}, "color is an array of uint8; vkray.denoise takes linear radiance as floats"),
    ((np.zeros((6, 8), np.float32),), {}, "color has shape (6, 8); vkray.denoise takes (height, width, 3) arrays"),
    ((np.zeros((6, 8, 4), np.float32),), {}, "color has shape (6, 8, 4)"),
    ((np.zeros((0, 8, 3), np.float32),), {}, "color has shape (0, 8, 3)"),
    ((IMAGE, np.zeros((6, 7, 3), np.float32)), {}, "albedo has shape (6, 7, 3), and color (6, 8, 3)"),
    ((IMAGE,), {"normal": IMAGE}, "normal is given without albedo"),
    ((IMAGE, IMAGE, np.zeros((6, 8, 3), np.int32)), {}, "normal is an array of int32"),
    (({"albedo": IMAGE},), {}, "the render's dict has no 'color' (it has 'albedo')"),
    (({"color": IMAGE},), {"albedo": IMAGE}, "color is a render's dict, which holds the guides"),
    ((IMAGE,), {"quality": "best"}, "quality is 'best'; it is one of high, balanced, fast"),
    ((["a", "b"],), {}, "color is an array of <U1"),
])
def test_arrays_of_the_wrong_shape_or_type_are_usage_errors(args, kwargs, says):
    with pytest.raises(vkray.UsageError) as error:
        vkray.denoise(*args, **kwargs)
    assert says in str(error.value)


def test_without_pyoidn_the_message_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # import pyoidn raises ModuleNotFoundError
    with pytest.raises(ModuleNotFoundError) as error:
        vkray.denoise(IMAGE)
    assert "needs Intel Open Image Denoise (pyoidn)" in str(error.value) and "pip install" in str(error.value)
    assert error.value.name == "pyoidn"


def test_without_pyoidn_a_denoised_render_fails_before_it_renders(monkeypatch, scenes):
    monkeypatch.setitem(sys.modules, "pyoidn", None)
    with vkray.Renderer() as r:
        with pytest.raises(ModuleNotFoundError):
            r.render(scenes / "cornell.json", width=16, height=16, denoise=True)
        assert r.last_stats is None  # nothing was rendered


def test_an_oidn_that_cannot_run_is_a_device_error_before_the_render(monkeypatch, scenes):
    monkeypatch.setitem(sys.modules, "pyoidn", UnloadablePyoidn())
    with pytest.raises(vkray.DeviceError, match="Open Image Denoise .* cannot run: cannot load library"):
        vkray.denoise(IMAGE)
    with vkray.Renderer() as r:
        with pytest.raises(vkray.DeviceError):
            r.render(scenes / "cornell.json", width=16, height=16, denoise=True)
        assert r.last_stats is None  # nothing was rendered


def test_a_region_is_not_denoised_alone(scenes):
    with pytest.raises(vkray.UsageError) as error:
        vkray.render(scenes / "cornell.json", width=16, height=16, region="1/2", denoise=True)
    assert "denoise=True with a region" in str(error.value)
    with pytest.raises(vkray.UsageError):
        vkray.render(scenes / "cornell.json", width=16, height=16, denoise="yes")


def relative_mse(image, reference):
    """The mean of (image - reference)^2 / (reference^2 + 0.01), per channel: the figure denoisers are
    compared by, where the light's HDR values would swamp a plain squared error."""
    return float(np.mean((image.astype(np.float64) - reference) ** 2 / (reference ** 2 + 1e-2)))


@needs_oidn
def test_a_few_samples_denoised_come_closer_to_many_samples(scenes):
    scene = scenes / "cornell-path.json"
    size = {"width": 64, "height": 64}
    reference = vkray.render(scene, spp=512, **size).astype(np.float64)
    noisy = vkray.render(scene, spp=8, aovs=("albedo", "normal"), **size)
    denoised = vkray.denoise(noisy)
    assert denoised.shape == (64, 64, 3) and denoised.dtype == np.float32
    assert relative_mse(denoised, reference) < 0.4 * relative_mse(noisy["color"], reference)
    # One call does the same: the render's colour and its two guides, denoised.
    assert np.array_equal(vkray.render(scene, spp=8, denoise=True, **size), denoised)


@needs_oidn
def test_passes_asked_for_come_back_beside_the_denoised_colour(scenes):
    result = vkray.render(scenes / "cornell-spheres.json", width=32, height=24, spp=2, aovs="depth", denoise=True)
    assert sorted(result) == ["color", "depth"]
    assert result["color"].shape == (24, 32, 3) and result["depth"].shape == (24, 32)
    on_cpu = vkray.render(scenes / "cornell-spheres.json", width=32, height=24, spp=2, renderer="cpu", denoise=True)
    assert on_cpu.shape == (24, 32, 3) and np.isfinite(on_cpu).all()


@needs_oidn
def test_values_a_render_does_not_have_are_sanitised_not_passed_on():
    color = np.full((16, 16, 3), 0.25, np.float32)
    color[3, 4] = np.nan
    color[5, 6] = np.inf
    color[7, 8] = -1.0
    albedo = np.full((16, 16, 3), 2.0, np.float32)  # past 1: clamped
    albedo[1, 1] = np.nan
    normal = np.zeros((16, 16, 3), np.float32)
    normal[..., 2] = 5.0  # past 1: clamped
    out = vkray.denoise(color, albedo, normal)
    assert np.isfinite(out).all()
    assert 0.15 < float(out.mean()) < 0.35


# ---- image files: vkray.read_image and vkray.write_image ------------------------------------------

def test_an_exr_with_every_pass_reads_back_as_written(tmp_path):
    rng = np.random.default_rng(1)
    arrays = {"color": rng.random((5, 7, 3), np.float32) * 10, "albedo": rng.random((5, 7, 3), np.float32),
              "normal": rng.random((5, 7, 3), np.float32) * 2 - 1, "position": rng.random((5, 7, 3), np.float32),
              "depth": rng.random((5, 7), np.float32), "object": rng.integers(-1, 9, (5, 7)).astype(np.int32)}
    vkray.write_image(tmp_path / "all.exr", arrays, exr_float=True)
    back = vkray.read_image(tmp_path / "all.exr")
    assert list(back) == ["color", "albedo", "normal", "position", "depth", "object"]
    for name, value in arrays.items():
        assert back[name].dtype == value.dtype and np.array_equal(back[name], value), name
    vkray.write_image(tmp_path / "color.pfm", arrays["color"])
    assert list(vkray.read_image(tmp_path / "color.pfm")) == ["color"]
    assert np.array_equal(vkray.read_image(tmp_path / "color.pfm")["color"], arrays["color"])


@pytest.mark.parametrize("file, arrays, says", [
    ("x.exr", {"albedo": IMAGE}, 'no "color"'),
    ("x.exr", {"color": IMAGE, "albedo": np.zeros((6, 7, 3), np.float32)}, "albedo has shape (6, 7, 3); it must be (6, 8, 3)"),
    ("x.exr", {"color": IMAGE, "depth": IMAGE}, "depth has shape (6, 8, 3); it must be (6, 8)"),
    ("x.exr", {"color": IMAGE, "object": np.zeros((6, 8), np.float32)}, "object is an array of float32; it holds integers"),
    ("x.exr", {"color": IMAGE, "shadow": IMAGE}, '"shadow" is not an image vkray writes'),
    ("x.pfm", {"color": IMAGE, "albedo": IMAGE}, "pfm"),
])
def test_what_a_file_cannot_hold_is_a_usage_error_and_nothing_is_written(tmp_path, file, arrays, says):
    with pytest.raises(vkray.UsageError) as error:
        vkray.write_image(tmp_path / file, arrays)
    assert says in str(error.value)
    assert list(tmp_path.iterdir()) == []


def test_a_png_or_a_part_is_not_read_as_radiance(tmp_path, scenes):
    vkray.write_image(tmp_path / "x.png", IMAGE)
    with pytest.raises(vkray.UsageError, match="a PNG holds 8-bit display values"):
        vkray.read_image(tmp_path / "x.png")
    with vkray.Renderer() as r:
        r.render_to_file(scenes / "cornell.json", tmp_path / "part.exr", width=16, height=16, region="0/2")
    with pytest.raises(vkray.UsageError, match="a part of a render"):
        vkray.read_image(tmp_path / "part.exr")
    (tmp_path / "bad.exr").write_bytes(b"not an exr")
    with pytest.raises(vkray.SceneError, match="bad.exr"):
        vkray.read_image(tmp_path / "bad.exr")


# ---- python3 -m vkray.denoise --------------------------------------------------------------------

def denoise_command(args, capsys):
    from vkray.denoise import main
    code = main([str(a) for a in args])
    return code, capsys.readouterr().err


@pytest.fixture
def render_with_guides(tmp_path, scenes):
    path = tmp_path / "render.exr"
    with vkray.Renderer() as r:
        r.render_to_file(scenes / "cornell-path.json", path, width=48, height=32, spp=4, aovs="albedo,normal,depth")
    return path


def test_a_file_without_the_guides_is_bad_input_and_nothing_is_written(tmp_path, scenes, capsys):
    plain = tmp_path / "plain.exr"
    with vkray.Renderer() as r:
        r.render_to_file(scenes / "cornell-path.json", plain, width=16, height=16, spp=1)
    code, err = denoise_command([plain, "-o", tmp_path / "out.exr"], capsys)
    assert code == 1 and "has no albedo and no normal pass" in err and "--aov albedo,normal" in err
    assert not (tmp_path / "out.exr").exists()


@pytest.mark.parametrize("extra, says", [
    (["--spp", "4"], "--spp: for a scene to render"),
    (["--exr-float"], "exr-float"),
])
def test_options_that_do_not_fit_are_usage_errors(render_with_guides, tmp_path, capsys, extra, says):
    code, err = denoise_command([render_with_guides, "-o", tmp_path / "out.png", *extra], capsys)
    assert code == 2 and says in err
    assert not (tmp_path / "out.png").exists()


def test_without_pyoidn_the_command_says_so_before_any_work(render_with_guides, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)
    code, err = denoise_command([render_with_guides, "-o", tmp_path / "out.exr"], capsys)
    assert code == 1 and "needs Intel Open Image Denoise (pyoidn)" in err
    assert not (tmp_path / "out.exr").exists()


def test_an_oidn_that_cannot_run_exits_3_and_writes_nothing(render_with_guides, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", UnloadablePyoidn())
    code, err = denoise_command([render_with_guides, "-o", tmp_path / "out.exr"], capsys)
    assert code == 3 and "vkray.denoise: error: Open Image Denoise" in err and "Traceback" not in err, err
    assert not (tmp_path / "out.exr").exists()


def test_passes_for_an_output_that_is_not_an_exr_are_refused_as_vkray_render_refuses_them(tmp_path, scenes, capsys):
    code, err = denoise_command([scenes / "cornell-path.json", "--aov", "depth", "-o", tmp_path / "out.png"], capsys)
    assert code == 2 and "written to EXR files only" in err, err
    assert list(tmp_path.iterdir()) == []


# A pyoidn that opens its device and is never asked to denoise: the command renders as with OIDN.
# It says "opened" when the command opens it, just before the render (its signal handlers are set).
FAKE_PYOIDN_THEN_RUN = """
import runpy, sys, types
class Device:
    def __enter__(self): return self
    def __exit__(self, *exc): return False
    def commit(self): print("opened", flush=True)
    def get_error(self): return None
sys.modules["pyoidn"] = types.SimpleNamespace(Device=Device, __file__="fake")
sys.argv[0] = "vkray.denoise"
runpy.run_module("vkray.denoise", run_name="__main__", alter_sys=True)
"""


def test_sigterm_stops_the_command_as_ctrl_c_does_and_nothing_is_written(tmp_path, scenes):
    job = subprocess.Popen([sys.executable, "-c", FAKE_PYOIDN_THEN_RUN, scenes / "cornell-path.json", "--width", "256",
                            "--height", "256", "--spp", "65536", "-o", tmp_path / "out.exr"],
                           cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert job.stdout.readline() == "opened\n", job.communicate()[1]
        time.sleep(0.5)  # into the render, which takes minutes
        assert job.poll() is None, job.communicate()[1]
        job.send_signal(signal.SIGTERM)
        err = job.communicate(timeout=60)[1]
    finally:
        job.kill()
    assert job.returncode == 130, err
    assert "vkray.denoise: interrupted; nothing written" in err, err
    assert list(tmp_path.iterdir()) == []


@needs_oidn
def test_an_exr_keeps_its_passes_and_gets_the_denoised_colour(render_with_guides, tmp_path, capsys):
    code, err = denoise_command([render_with_guides, "-o", tmp_path / "out.exr"], capsys)
    assert code == 0, err
    before, after = vkray.read_image(render_with_guides), vkray.read_image(tmp_path / "out.exr")
    assert list(after) == ["color", "albedo", "normal", "depth"]
    for name in ("albedo", "normal", "depth"):
        assert np.array_equal(after[name], before[name]), name
    expected = vkray.denoise(before["color"], before["albedo"], before["normal"])
    assert np.array_equal(after["color"], expected.astype(np.float16).astype(np.float32))  # a half-float EXR


@needs_oidn
def test_a_scene_is_rendered_with_the_guides_and_denoised(tmp_path, scenes, capsys):
    code, err = denoise_command([scenes / "cornell-path.json", "--width", "48", "--height", "32", "--spp", "4",
                                 "-o", tmp_path / "out.pfm"], capsys)
    assert code == 0, err
    expected = vkray.render(scenes / "cornell-path.json", width=48, height=32, spp=4, denoise=True)
    assert np.array_equal(vkray.read_image(tmp_path / "out.pfm")["color"], expected)


# ---- python3 -m vkray.farm --denoise -------------------------------------------------------------

@needs_oidn
def test_a_farm_job_denoises_the_merged_frames_as_one_render_would(tmp_path, scenes, capsys):
    pytest.importorskip("distributed", reason="the farm needs Dask's distributed (vkray[farm])")
    size = ["--width", "64", "--height", "48", "--spp", "4"]
    farm = subprocess.run([sys.executable, "-m", "vkray.farm", scenes / "cornell-path.json", *size, "--aov", "depth",
                           "--workers", "2", "--regions", "4", "--denoise", "-o", tmp_path / "farm.exr"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert farm.returncode == 0, farm.stderr
    assert "denoised frame 0 (64x48)" in farm.stderr, farm.stderr
    # A denoiser looks across the bands' edges: the frame is denoised whole, after the merge, and
    # is the image the denoiser gives a single render, with the guides kept beside the passes asked for.
    code, err = denoise_command([scenes / "cornell-path.json", *size, "--aov", "depth", "-o", tmp_path / "one.exr"],
                                capsys)
    assert code == 0, err
    assert (tmp_path / "farm.exr").read_bytes() == (tmp_path / "one.exr").read_bytes()
    assert list(vkray.read_image(tmp_path / "farm.exr")) == ["color", "albedo", "normal", "depth"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["farm.exr", "one.exr"]  # the parts are gone
