"""vkray.render, vkray.Renderer, vkray.parity and vkray.devices against the command line and
against what a scene's geometry says."""

import json
import threading
import time

import numpy as np
import pytest

import vkray
from conftest import read_pfm, run

SMALL = dict(width=64, height=48)


def test_render_returns_what_the_command_line_writes_as_pfm(scenes, vkray_command, tmp_path):
    image = vkray.render(scenes / "cornell-spheres.json", spp=2, **SMALL)
    assert image.shape == (48, 64, 3) and image.dtype == np.float32
    run(vkray_command, "render", str(scenes / "cornell-spheres.json"), "--width", "64", "--height", "48", "--spp", "2",
        "-o", str(tmp_path / "x.pfm"), "-q")
    assert np.array_equal(image, read_pfm(tmp_path / "x.pfm"))


def test_an_environment_map_lights_a_scene_as_the_command_line_does(scenes, vkray_command, tmp_path):
    box = scenes / "gltf" / "BoxTextured" / "glTF-Binary" / "BoxTextured.glb"
    sky = scenes / "skies" / "daylight.exr"
    image = vkray.render(box, environment=sky, spp=2, **SMALL)
    run(vkray_command, "render", str(box), "--environment", str(sky), "--width", "64", "--height", "48", "--spp", "2",
        "-o", str(tmp_path / "x.pfm"), "-q")
    assert np.array_equal(image, read_pfm(tmp_path / "x.pfm"))
    assert image[0, 0].sum() > 0  # the sky, beside the box
    with pytest.raises(vkray.SceneError, match="nowhere.hdr: not found"):
        vkray.render(box, environment=tmp_path / "nowhere.hdr", **SMALL)


def test_the_cpu_reference_renders_the_same_scene(scenes):
    gpu = vkray.render(scenes / "cornell.json", **SMALL)
    cpu = vkray.render(scenes / "cornell.json", renderer="cpu", threads=2, **SMALL)
    assert cpu.shape == gpu.shape
    # Edges may differ by a sample's rounding; the images agree everywhere else.
    assert np.mean(np.abs(cpu - gpu) > 1e-3) < 0.02


def test_a_scene_dict_takes_numpy_arrays_and_resolves_meshes_against_base_dir(scenes):
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32)
    scene = {
        "camera": {"position": np.array([0.0, 0.0, 3.0]), "look_at": [0, 0, 0], "vertical_fov": 50},
        "lights": [{"type": "point", "position": [0, 0, 3], "intensity": np.float32(9.0) * np.ones(3)}],
        "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
        "objects": [
            {"type": "triangles", "material": "white", "positions": positions, "indices": np.array([[0, 1, 2], [0, 2, 3]])},
            {"type": "mesh", "file": "meshes/teapot.obj", "material": "white", "transform": {"scale": 0.1}},
        ],
    }
    image = vkray.render(scene, base_dir=scenes, **SMALL)
    assert image[24, 32].min() > 0.1  # the quad, lit head on
    with pytest.raises(vkray.SceneError, match="meshes/teapot.obj"):
        vkray.render(scene, base_dir=scenes / "nowhere", **SMALL)


def test_aovs_come_back_as_a_dict_of_arrays(scenes):
    out = vkray.render(scenes / "cornell-spheres.json", aovs=vkray.AOVS, spp=4, **SMALL)
    assert set(out) == {"color", *vkray.AOVS}
    for name in ("color", "albedo", "normal", "position"):
        assert out[name].shape == (48, 64, 3) and out[name].dtype == np.float32
    assert out["depth"].shape == (48, 64) and out["depth"].dtype == np.float32
    assert out["object"].shape == (48, 64) and out["object"].dtype == np.int32
    # The box fills the middle of the image; past its sides nothing is hit.
    missed = np.isinf(out["depth"])
    assert 0 < missed.mean() < 0.5 and (out["depth"][~missed] > 0).all()
    assert (out["object"][missed] == -1).all() and (out["object"][24, 16:48] >= 0).all()
    assert (out["albedo"][missed] == 0).all()
    # A position is the camera plus depth along the ray: the depth is the distance to it.
    camera = np.array(json.loads((scenes / "cornell-spheres.json").read_text())["camera"]["position"], dtype=np.float64)
    distance = np.linalg.norm(out["position"] - camera, axis=2)
    interior = ~missed & (out["object"] == np.roll(out["object"], 1, axis=1)) & (out["object"] == np.roll(out["object"], 1, axis=0))
    assert np.allclose(distance[interior], out["depth"][interior], rtol=1e-3)
    single = vkray.render(scenes / "cornell.json", aovs="depth,object", **SMALL)
    assert set(single) == {"color", "depth", "object"}


def test_a_renderer_reuses_the_geometry_when_the_camera_moves(scenes):
    scene = json.loads((scenes / "bunny.json").read_text())
    with vkray.Renderer(validate=True) as r:
        first = r.render(scene, base_dir=scenes, **SMALL)
        assert r.last_stats["geometry_reused"] is False
        scene["camera"]["position"][0] += 0.05
        scene["lights"][0]["position"][1] += 1.0
        scene["materials"]["clay"]["albedo"] = [0.2, 0.7, 0.3]
        moved = r.render(scene, base_dir=scenes, **SMALL)
        assert r.last_stats["geometry_reused"] is True
        assert not np.array_equal(first, moved)
        assert np.array_equal(moved, vkray.render(scene, base_dir=scenes, **SMALL))
        scene["objects"][0]["transform"] = {"scale": 1.01}
        r.render(scene, base_dir=scenes, **SMALL)
        assert r.last_stats["geometry_reused"] is False
    assert r.device == ""


def test_errors_raise_the_command_lines_messages(scenes, vkray_command, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"camera": {"position": [0, 0, 0], "look_at": [0, 0, 0]}}')
    with pytest.raises(vkray.SceneError) as caught:
        vkray.render(bad)
    cli = run(vkray_command, "render", str(bad), "-o", str(tmp_path / "x.png"), check=False)
    assert cli.returncode == 1
    assert str(caught.value) in cli.stderr
    with pytest.raises(vkray.DeviceError) as caught:
        vkray.render(scenes / "cornell.json", device="no such device", **SMALL)
    cli = run(vkray_command, "render", str(scenes / "cornell.json"), "--device", "no such device", "-o", str(tmp_path / "x.png"),
              check=False)
    assert cli.returncode == 3 and str(caught.value) in cli.stderr
    with pytest.raises(vkray.UsageError):
        vkray.render(scenes / "cornell.json", width=0)
    with pytest.raises(vkray.UsageError, match="unknown pass"):
        vkray.render(scenes / "cornell.json", aovs=["albedo", "colour"])
    with pytest.raises(vkray.SceneError, match="<scene dict>: /camera"):
        vkray.render({"camera": {}})
    with pytest.raises(vkray.SceneError):
        vkray.render({"camera": {"position": [float("nan"), 0, 0]}})
    assert issubclass(vkray.SceneError, vkray.Error) and issubclass(vkray.DeviceError, vkray.Error)


def test_rendering_releases_the_gil(scenes):
    # The CPU reference on one thread: a render that lasts long on any device (a fast GPU could end
    # one before the main thread looked), through the same call path as the GPU's.
    done = threading.Event()
    result = {}

    def work():
        result["image"] = vkray.render(scenes / "cornell.json", width=128, height=128, spp=64, renderer="cpu", threads=1)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    thread.join()
    assert result["image"].shape == (128, 128, 3)
    assert ticks > 20, "the main thread did not run while the render did"


def test_parity_returns_the_json_keys_of_the_command_line(scenes, vkray_command):
    result = vkray.parity(scenes / "cornell.json", **SMALL)
    cli = json.loads(run(vkray_command, "parity", str(scenes / "cornell.json"), "--width", "64", "--height", "48", "--json").stdout)
    assert set(result) == set(cli)
    assert result["pass"] is True and result["aov_pixels_differing"] == cli["aov_pixels_differing"]


def test_devices_lists_the_lavapipe_device():
    found = vkray.devices()
    assert found and found[0]["index"] == 0
    assert any(d["type"] == "CPU" and d["compute"] for d in found)


def test_scene_warnings_are_python_warnings(scenes):
    scene = json.loads((scenes / "cornell.json").read_text())
    scene["colour_of_the_sky"] = "blue"
    with pytest.warns(UserWarning, match="colour_of_the_sky.*unknown key"):
        vkray.render(scene, base_dir=scenes, width=8, height=8)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning):
            vkray.render(scene, base_dir=scenes, width=8, height=8)
