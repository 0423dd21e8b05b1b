"""EXR files from `vkray render` read by tools that are not vkray: OpenImageIO (the pixels) and
OpenEXR's own exrheader (the channel list and types)."""

import numpy as np
import OpenImageIO as oiio
import pytest

import vkray
from conftest import run

LAYERS = ["R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z", "position.X",
          "position.Y", "position.Z", "depth.Z", "object.id"]


def read_exr(path):
    """The file's channels by name, each a (height, width) float32 array, with OpenImageIO."""
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return {name: pixels[:, :, c] for c, name in enumerate(spec.channelnames)}, spec


@pytest.fixture
def rendered(scenes):
    """The Cornell box with spheres, 4 spp, and its passes, from Python."""
    return vkray.render(scenes / "cornell-spheres.json", width=64, height=48, spp=4, aovs=vkray.AOVS)


def test_a_full_float_exr_holds_the_image_and_every_pass_exactly(scenes, vkray_command, tmp_path, rendered):
    out = tmp_path / "x.exr"
    run(vkray_command, "render", str(scenes / "cornell-spheres.json"), "--width", "64", "--height", "48", "--spp", "4",
        "--aov", "albedo,normal,position,depth,object", "--exr-float", "-o", str(out), "-q")
    channels, spec = read_exr(out)
    assert sorted(channels) == sorted(LAYERS)
    assert (spec.width, spec.height) == (64, 48)
    for c, name in enumerate("RGB"):
        assert np.array_equal(channels[name], rendered["color"][:, :, c])
    for layer, axes in (("albedo", "RGB"), ("normal", "XYZ"), ("position", "XYZ")):
        for c, axis in enumerate(axes):
            assert np.array_equal(channels[f"{layer}.{axis}"], rendered[layer][:, :, c]), f"{layer}.{axis}"
    assert np.array_equal(channels["depth.Z"], rendered["depth"])
    assert np.array_equal(channels["object.id"].astype(np.int32), rendered["object"])


def test_a_default_exr_is_half_float_with_32_bit_lengths_and_object_ids(scenes, vkray_command, tmp_path, rendered):
    out = tmp_path / "h.EXR"  # the extension in any case
    run(vkray_command, "render", str(scenes / "cornell-spheres.json"), "--width", "64", "--height", "48", "--spp", "4",
        "--aov", "depth,object,normal", "-o", str(out), "-q")
    header = run("exrheader", str(out)).stdout
    for name in ("R", "G", "B", "normal.X"):
        assert f"    {name}, 16-bit floating-point" in header, header
    for name in ("depth.Z", "object.id"):
        assert f"    {name}, 32-bit floating-point" in header, header
    assert "albedo.R" not in header
    channels, _ = read_exr(out)
    assert np.allclose(channels["R"], rendered["color"][:, :, 0], rtol=1e-3, atol=1e-6)
    assert np.array_equal(channels["depth.Z"], rendered["depth"])
    assert np.array_equal(channels["object.id"].astype(np.int32), rendered["object"])


def test_a_miss_has_infinite_depth_and_no_object(vkray_command, tmp_path):
    scene = tmp_path / "sky.json"
    scene.write_text('{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "vertical_fov": 40},'
                     ' "background": [0.1, 0.2, 0.3],'
                     ' "objects": [{"type": "sphere", "center": [0, 0, -5], "radius": 1, "material": "m"}],'
                     ' "materials": {"m": {"albedo": [0.5, 0.5, 0.5]}}, "lights": [{"type": "point", "position": [0, 0, 0],'
                     ' "intensity": [1, 1, 1]}]}')
    out = tmp_path / "sky.exr"
    run(vkray_command, "render", str(scene), "--width", "32", "--height", "32", "--aov", "depth,object", "-o", str(out), "-q")
    channels, _ = read_exr(out)
    assert np.isposinf(channels["depth.Z"][0, 0]) and channels["object.id"][0, 0] == -1
    assert np.isfinite(channels["depth.Z"][16, 16]) and channels["object.id"][16, 16] == 0


def test_passes_need_an_exr_file_and_nothing_is_written_otherwise(scenes, vkray_command, tmp_path):
    result = run(vkray_command, "render", str(scenes / "cornell.json"), "--aov", "depth", "-o", str(tmp_path / "x.png"),
                 check=False)
    assert result.returncode == 2 and "EXR" in result.stderr
    result = run(vkray_command, "render", str(scenes / "cornell.json"), "--aov", "depth,colour", "-o", str(tmp_path / "x.exr"),
                 check=False)
    assert result.returncode == 2 and "colour" in result.stderr
    assert list(tmp_path.iterdir()) == []
