"""The Python face checks what the command line checks, with the same messages and the same classes
of error: an argument out of range or of the wrong kind is a vkray.UsageError naming it (exit 2 in
the command line), a scene dict value that JSON cannot hold is a vkray.SceneError naming its key
(exit 1), and a warning turned into an error stops a render before it writes anything."""

import json
import warnings

import numpy as np
import pytest

import vkray
from conftest import run

SMALL = dict(width=16, height=12)


def cli_message(vkray_command, tmp_path, *args: str) -> str:
    """The message `vkray render` prints for `args`, after the flag's name; it must exit 2."""
    result = run(vkray_command, "render", *args, "-o", str(tmp_path / "x.png"), check=False)
    assert result.returncode == 2, result.stderr
    flag = args[0]
    line = next(line for line in result.stderr.splitlines() if f"{flag}: " in line)
    return line.split(f"{flag}: ", 1)[1]


# (keyword, value, the command line's flag and text for the same number, or None where it has none)
OUT_OF_RANGE = [
    ("width", 0, "0"), ("width", -1, "-1"), ("width", 16385, "16385"), ("width", 10**20, str(10**20)),
    ("height", -1, "-1"), ("spp", 0, "0"), ("spp", 70000, "70000"),
    ("seed", -1, "-1"), ("seed", 2**32, str(2**32)),
    ("threads", -1, "-1"), ("threads", 10**6, str(10**6)),
]


@pytest.mark.parametrize("name,value,text", OUT_OF_RANGE)
def test_a_number_out_of_range_is_the_command_lines_usage_error(scenes, vkray_command, tmp_path, name, value, text):
    extra = {"renderer": "cpu"} if name == "threads" else {}
    with pytest.raises(vkray.UsageError) as caught:
        vkray.render(scenes / "cornell.json", **{**SMALL, name: value}, **extra)
    cli_args = ("--renderer", "cpu") if name == "threads" else ()
    expected = cli_message(vkray_command, tmp_path, f"--{name}", text, *cli_args)
    assert str(caught.value) == f"{name}: {expected}"


@pytest.mark.parametrize("value", [1.5, 64.0, True, False, "64", b"64", np.float32(8), np.bool_(True), [64], 1j])
@pytest.mark.parametrize("name", ["width", "height", "spp", "seed"])
def test_a_number_of_the_wrong_kind_is_a_usage_error_naming_it(scenes, name, value):
    with pytest.raises(vkray.UsageError, match=f"^{name}: expected an integer from"):
        vkray.render(scenes / "cornell.json", **{**SMALL, name: value})


def test_numpy_integers_are_numbers(scenes):
    image = vkray.render(scenes / "cornell.json", width=np.int64(16), height=np.uint16(12), spp=np.int32(1))
    assert image.shape == (12, 16, 3)


def test_threads_are_checked_on_every_call_that_takes_them(scenes):
    for value in (-1, 257, 2.0, True):
        with pytest.raises(vkray.UsageError, match="^threads: expected an integer from 1 to 256"):
            vkray.render(scenes / "cornell.json", renderer="cpu", threads=value, **SMALL)
        with pytest.raises(vkray.UsageError, match="^threads: expected an integer from 1 to 256"):
            vkray.parity(scenes / "cornell.json", threads=value, **SMALL)
    # 0, the default, is one per hardware thread.
    assert vkray.render(scenes / "cornell.json", renderer="cpu", threads=0, **SMALL).shape == (12, 16, 3)


def test_parity_and_bands_check_their_numbers(scenes):
    with pytest.raises(vkray.UsageError, match="^spp: expected an integer from 1 to 65536, got -2"):
        vkray.parity(scenes / "cornell.json", spp=-2, **SMALL)
    for count in (-1, 0, 1.0, None, True):
        with pytest.raises(vkray.UsageError, match="^count: expected an integer from 1 to 16384"):
            vkray.bands(scenes / "cornell.json", count, **SMALL)
    with pytest.raises(vkray.UsageError, match="^height: expected an integer from 1 to 16384, got -12"):
        vkray.bands(scenes / "cornell.json", 2, width=16, height=-12)


@pytest.mark.parametrize("region", [b"0/10", bytearray(b"0/2"), (0, 0, 8), (0, 0, 8.0, 6), (True, 0, 8, 6), 5, {"x": 1}])
def test_a_region_of_the_wrong_kind_is_a_usage_error(scenes, region):
    # 64x64: the bytes of b"0/10" read as numbers (48, 47, 49, 48) make a region inside the image.
    with pytest.raises(vkray.UsageError, match="^a region is"):
        vkray.render(scenes / "cornell.json", region=region, width=64, height=64)


def test_a_region_as_text_or_numbers_still_renders(scenes):
    whole = vkray.render(scenes / "cornell.json", **SMALL)
    assert np.array_equal(vkray.render(scenes / "cornell.json", region=np.array([0, 2, 16, 5]), **SMALL), whole[2:5])
    assert vkray.render(scenes / "cornell.json", region="0/2", **SMALL).shape[1] == 16


def test_other_arguments_of_the_wrong_kind_are_usage_errors(scenes, tmp_path):
    for call in (lambda: vkray.render(scenes / "cornell.json", aovs=b"albedo", **SMALL),
                 lambda: vkray.render(scenes / "cornell.json", aovs=["albedo", 3], **SMALL),
                 lambda: vkray.render(3.5),
                 lambda: vkray.render({"camera": {}}, base_dir=3),
                 lambda: vkray.Renderer(validate="yes"),
                 lambda: vkray.parity(scenes / "cornell.json", validate=1, **SMALL)):
        with pytest.raises(vkray.UsageError):
            call()
    with vkray.Renderer() as renderer:
        with pytest.raises(vkray.UsageError, match="^exr_float"):
            renderer.render_to_file(scenes / "cornell.json", tmp_path / "x.exr", exr_float="no", **SMALL)
        with pytest.raises(vkray.UsageError, match="^output"):
            renderer.render_to_file(scenes / "cornell.json", 42, **SMALL)
    assert list(tmp_path.iterdir()) == []


CAMERA = {"position": [0, 0, 3], "look_at": [0, 0, 0], "vertical_fov": 40}


@pytest.mark.parametrize("value,pointer,what", [
    (float("nan"), "/camera/position/0", "nan is not a value a scene can hold"),
    (float("inf"), "/camera/position/0", "inf is not a value a scene can hold"),
    (np.float64("-inf"), "/camera/position/0", "-inf is not a value a scene can hold"),
    (1j, "/camera/position/0", "a Python complex is not a value a scene can hold"),
    (object(), "/camera/position/0", "a Python object is not a value a scene can hold"),
    ({1, 2}, "/camera/position/0", "a Python set is not a value a scene can hold"),
    ("\ud800", "/camera/position/0", "is not valid Unicode text"),
])
def test_a_scene_dict_value_json_cannot_hold_is_a_scene_error_naming_its_key(value, pointer, what):
    scene = {"camera": {**CAMERA, "position": [value, 0, 3]}}
    with pytest.raises(vkray.SceneError) as caught:
        vkray.render(scene, **SMALL)
    assert f"<scene dict>: {pointer}: " in str(caught.value) and what in str(caught.value), str(caught.value)


def test_numpy_arrays_in_a_scene_dict_name_the_element_that_is_not_finite():
    positions = np.zeros((4, 3), dtype=np.float32)
    positions[2, 1] = np.nan
    scene = {"camera": CAMERA, "objects": [{"type": "triangles", "positions": positions, "indices": [[0, 1, 2]]}]}
    with pytest.raises(vkray.SceneError, match=r"<scene dict>: /objects/0/positions/2/1: nan is not a value"):
        vkray.render(scene, **SMALL)
    scene["objects"][0]["positions"] = np.array([[0, 0, 0], [1, 0, 0], [0, 1j, 0]], dtype=object)
    with pytest.raises(vkray.SceneError, match=r"<scene dict>: /objects/0/positions/2/1: a Python complex is not"):
        vkray.render(scene, **SMALL)


def test_a_key_that_is_not_text_is_a_scene_error():
    with pytest.raises(vkray.SceneError, match=r"<scene dict>: /materials: a key is text, not a int \(1\)"):
        vkray.render({"camera": CAMERA, "materials": {1: {"albedo": [1, 1, 1]}}}, **SMALL)


def test_nesting_past_the_limit_says_what_the_scene_parser_says(tmp_path, vkray_command):
    deep = [0]
    for _ in range(100):
        deep = [deep]
    scene = {"camera": CAMERA, "extra": deep}
    (tmp_path / "deep.json").write_text(json.dumps(scene))
    cli = run(vkray_command, "render", str(tmp_path / "deep.json"), "-o", str(tmp_path / "x.png"), check=False)
    assert cli.returncode == 1
    with pytest.raises(vkray.SceneError) as caught:
        vkray.render(scene, base_dir=tmp_path, **SMALL)
    after_file = str(caught.value).split("<scene dict>: ", 1)[1]
    assert "nesting deeper than 64 levels" in after_file
    assert cli.stderr.split("deep.json: ", 1)[1].strip() == after_file


def test_a_warning_turned_error_stops_a_render_before_it_writes(scenes, tmp_path):
    scene = json.loads((scenes / "cornell.json").read_text())
    scene["colour_of_the_sky"] = "blue"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with vkray.Renderer() as renderer:
            for output, region in ((tmp_path / "x.png", None), (tmp_path / "part.exr", "0/2")):
                with pytest.raises(UserWarning, match="colour_of_the_sky"):
                    renderer.render_to_file(scene, output, region=region, base_dir=scenes, **SMALL)
                with pytest.raises(UserWarning, match="colour_of_the_sky"):
                    renderer.render(scene, base_dir=scenes, **SMALL)
                assert renderer.last_stats is None  # nothing was rendered either
        with pytest.raises(UserWarning):
            vkray.render(scene, base_dir=scenes, renderer="cpu", **SMALL)
        with pytest.raises(UserWarning):
            vkray.parity(scene, base_dir=scenes, **SMALL)
    assert list(tmp_path.iterdir()) == []
