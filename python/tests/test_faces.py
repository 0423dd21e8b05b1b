"""One taxonomy of failures for every face: the same mistake given to `vkray render` (or `vkray
merge`), to the Python module and to the farm ends in the same class, exit code 1 bad input, 2
usage, 3 device (docs/commands.md, "Exit codes"), and SceneError, UsageError or DeviceError in
Python, with the same words."""

import dataclasses
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import vkray

from conftest import run

# What each exit code is in Python.
EXCEPTION = {1: vkray.SceneError, 2: vkray.UsageError, 3: vkray.DeviceError}

SMALL = {"width": 16, "height": 16, "spp": 1}


@dataclasses.dataclass(frozen=True)
class Faces:
    """What differs by face: the command lines (`vkray render` and the farm) are given text, the
    Python module objects. A value, or the words each face's message holds."""
    command_line: str
    python: object


def on(face: str, value):
    """`value` as `face` ("command line" or "python") is given it, or says it."""
    return getattr(value, face.replace(" ", "_")) if isinstance(value, Faces) else value


def flags(settings: dict) -> list:
    return [f for key, value in settings.items() for f in (f"--{key}", str(on("command line", value)))]


def keywords(settings: dict) -> dict:
    return {key: on("python", value) for key, value in settings.items()}


def farm(*args: str, cwd: Path, env=None) -> subprocess.CompletedProcess:
    """The farm run to its end in a session of its own, killed with its workers if it overstays."""
    job = subprocess.Popen([sys.executable, "-m", "vkray.farm", *args, "-q"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True, start_new_session=True, cwd=cwd, env=env)
    try:
        out, err = job.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        os.killpg(job.pid, signal.SIGKILL)
        job.communicate()
        raise
    return subprocess.CompletedProcess(job.args, job.returncode, out, err)


def not_decimal(flag: str, text: str, limit: str) -> tuple:
    """A number written as the command line does not read one, given as that text to every face: the
    command lines say their decimal rule, Python that text is not an integer."""
    return ({flag: Faces(text, text)}, 2, Faces(f'--{flag}: expected a decimal integer, got "{text}"',
                                                f"{flag}: expected an integer from {limit}, got {text!r}"))


# (what is wrong, the scene, the output, settings, exit code, words every face's message holds),
# a setting or the words as a Faces where they differ by face.
MISTAKES = [
    ("scene file missing", "missing.json", "out.pfm", {}, 1, "missing.json"),
    ("output under a file", "{cornell}", "{cornell}/out.pfm", {}, 1, "cornell.json does not exist"),
    ("output of an unknown type", "{cornell}", "out.txt", {}, 1, "unknown image type"),
    ("output is a folder", "{cornell}", "folder.pfm", {}, 1, "folder.pfm: is a folder"),
    ("width past the limit", "{cornell}", "out.pfm", {"width": 20000}, 2, "width: expected an integer from 1 to 16384, got 20000"),
    ("width below the limit", "{cornell}", "out.pfm", {"width": 0}, 2, "width: expected an integer from 1 to 16384, got 0"),
    ("negative height", "{cornell}", "out.pfm", {"height": -5}, 2, "height: expected an integer from 1 to 16384, got -5"),
    ("samples past the limit", "{cornell}", "out.pfm", {"spp": 70000}, 2, "spp: expected an integer from 1 to 65536, got 70000"),
    ("negative seed", "{cornell}", "out.pfm", {"seed": -1}, 2, "seed: expected an integer from 0 to 4294967295, got -1"),
    # Leading zeros are decimal: 020000 is twenty thousand (not octal), past the limit.
    ("width with leading zeros", "{cornell}", "out.pfm", {"width": Faces("020000", 20000)}, 2,
     "width: expected an integer from 1 to 16384, got 20000"),
    ("width with underscores", "{cornell}", "out.pfm", *not_decimal("width", "1_000", "1 to 16384")),
    ("height with a plus sign", "{cornell}", "out.pfm", *not_decimal("height", "+5", "1 to 16384")),
    ("samples with a space", "{cornell}", "out.pfm", *not_decimal("spp", " 5", "1 to 65536")),
    ("seed in Arabic-Indic digits", "{cornell}", "out.pfm", *not_decimal("seed", "\u0663", "0 to 4294967295")),
    ("width in letters", "{cornell}", "out.pfm", *not_decimal("width", "abc", "1 to 16384")),
    ("a bad scene value", "{bad}", "out.pfm", {}, 1, "/objects/0/radius: expected a number > 0"),
]


@pytest.fixture
def workdir(tmp_path: Path, scenes: Path) -> dict:
    (tmp_path / "folder.pfm").mkdir()
    bad = tmp_path / "bad.json"
    bad.write_text('{"camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "vertical_fov": 40}, "objects": '
                   '[{"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": "m"}], '
                   '"materials": {"m": {"albedo": [0.5, 0.5, 0.5]}}}')
    return {"cwd": tmp_path, "cornell": str(scenes / "cornell.json"), "bad": str(bad)}


def resolve(text: str, w: dict) -> str:
    return text.format(cornell=w["cornell"], bad=w["bad"])


@pytest.mark.parametrize("what, scene, output, settings, code, says", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_a_mistake_is_the_same_class_on_every_face(workdir, vkray_command, what, scene, output, settings, code, says):
    scene, output, cwd = resolve(scene, workdir), resolve(output, workdir), workdir["cwd"]
    before = sorted(p.name for p in cwd.iterdir())

    cli = run(vkray_command, "render", scene, "-o", output, "-q", *flags({**SMALL, **settings}), check=False, cwd=cwd)
    assert cli.returncode == code, cli.stderr
    assert on("command line", says) in cli.stderr, cli.stderr

    os.chdir(cwd)
    with pytest.raises(EXCEPTION[code], match=None) as raised:
        with vkray.Renderer() as renderer:
            renderer.render_to_file(scene, output, **keywords({**SMALL, **settings}))
    assert on("python", says) in str(raised.value), raised.value

    job = farm(scene, "-o", output, *flags({**SMALL, **settings}), cwd=cwd)
    assert job.returncode == code, job.stderr
    assert on("command line", says) in job.stderr, job.stderr

    assert sorted(p.name for p in cwd.iterdir()) == before, "a face left a file behind"


def test_a_device_that_is_not_there_is_a_device_error_on_every_face(tmp_path, scenes, vkray_command):
    scene = str(scenes / "cornell.json")
    cli = run(vkray_command, "render", scene, "-o", str(tmp_path / "out.pfm"), "-q", "--device", "99", *flags(SMALL),
              check=False)
    assert cli.returncode == 3, cli.stderr
    with pytest.raises(vkray.DeviceError):
        vkray.render(scene, device="99", **SMALL)
    job = farm(scene, "-o", str(tmp_path / "out.pfm"), *flags(SMALL), "--workers", "1", cwd=tmp_path,
               env={**os.environ, "VKRAY_DEVICE": "99"})
    assert job.returncode == 3, job.stderr
    assert list(tmp_path.iterdir()) == []


def test_merge_refuses_alike_from_the_command_line_and_python(tmp_path, scenes, vkray_command):
    scene = str(scenes / "cornell.json")
    parts = [tmp_path / f"p{i}.pfm" for i in range(2)]
    for i, part in enumerate(parts):
        run(vkray_command, "render", scene, "-o", str(part), "-q", "--region", f"{i}/2", *flags(SMALL))
    picture = tmp_path / "whole.png"
    run(vkray_command, "render", scene, "-o", str(picture), "-q", *flags(SMALL))
    for output, inputs, says in [
        (tmp_path / "m.pfm", [parts[0], picture], "not a part of a render"),  # a PNG is no part
        (parts[0], parts, "is a part being merged"),                          # the output among its inputs
    ]:
        cli = run(vkray_command, "merge", str(output), *map(str, inputs), check=False)
        assert cli.returncode == 1, cli.stderr
        with pytest.raises(vkray.SceneError) as raised:
            vkray.merge(output, inputs)
        assert cli.stderr.strip().endswith(str(raised.value)), (cli.stderr, raised.value)
        assert says in str(raised.value), raised.value
    assert not (tmp_path / "m.pfm").exists()
