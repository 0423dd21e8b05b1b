"""EXR files from `vkray render` read by tools that are not vkray: OpenImageIO (the pixels) and
OpenEXR's own exrheader (the channel list and types); and EXR files that vkray reads (a merge's
parts) whose header claims more than the file or the machine can hold."""

import resource
import struct
import zlib

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


# ---- files that claim more than they hold ----------------------------------------------------------

def write_zip_exr(path, width, height):
    """A half-float RGB EXR of `width` x `height` pixels, ZIP-compressed, written by hand as the OpenEXR
    file layout describes it: every block of 16 scan lines holds the same compressed zeros, so a large
    image is a small file."""
    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    channels = b"".join(name + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for name in (b"B", b"G", b"R")) + b"\0"
    header = (struct.pack("<ii", 20000630, 2) + attribute("channels", "chlist", channels)
              + attribute("compression", "compression", b"\3") + attribute("dataWindow", "box2i", box)
              + attribute("displayWindow", "box2i", box) + attribute("lineOrder", "lineOrder", b"\0")
              + attribute("pixelAspectRatio", "float", struct.pack("<f", 1)) + attribute("screenWindowCenter", "v2f", bytes(8))
              + attribute("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    blocks = (height + 15) // 16
    # Zeros as OpenEXR's ZIP stores them: after its predictor, a first byte of 0 and then 128s.
    data = zlib.compress(b"\0" + b"\x80" * (16 * width * 3 * 2 - 1))
    table_end = len(header) + 8 * blocks
    chunk = 8 + len(data)
    with open(path, "wb") as out:
        out.write(header)
        out.write(b"".join(struct.pack("<Q", table_end + b * chunk) for b in range(blocks)))
        for b in range(blocks):
            out.write(struct.pack("<ii", 16 * b, len(data)) + data)


def merge_in_2_gib(vkray_command, tmp_path, part):
    """`vkray merge` of one EXR under a 2 GiB address space: too little for a 16384 x 16384 image."""
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
    return run(vkray_command, "merge", str(tmp_path / "out.exr"), str(part), check=False, preexec_fn=limit)


def test_a_small_file_claiming_a_huge_image_is_refused_for_its_claim(vkray_command, tmp_path):
    # 9 KiB of a file whose header says 16384 x 16384 pixels: refused for what the header claims
    # against what the file holds, before gigabytes are allocated for it (never a bare bad_alloc).
    whole = tmp_path / "whole.exr"
    write_zip_exr(whole, 16384, 16384)
    part = tmp_path / "claims.exr"
    part.write_bytes(whole.read_bytes()[:9 * 1024])
    result = merge_in_2_gib(vkray_command, tmp_path, part)
    assert result.returncode == 1, result.stderr
    assert "claims.exr: its header claims 16384 x 16384 pixels in 1024 blocks" in result.stderr, result.stderr
    assert "bad_alloc" not in result.stderr
    assert not (tmp_path / "out.exr").exists()


def test_an_image_too_large_for_memory_is_out_of_host_memory(vkray_command, tmp_path):
    # A well-formed file of 16384 x 16384 pixels (1.6 MB, compressed) that this process may not hold
    # in memory: bad input too large for this machine, exit 1, said so.
    part = tmp_path / "large.exr"
    write_zip_exr(part, 16384, 16384)
    result = merge_in_2_gib(vkray_command, tmp_path, part)
    assert result.returncode == 1, result.stderr
    assert "large.exr: out of host memory for its 16384 x 16384 pixels" in result.stderr, result.stderr
    assert "bad_alloc" not in result.stderr
    assert not (tmp_path / "out.exr").exists()
