"""`vkray view` driven as a user drives it: real X events (xdotool) into its window on a virtual
display (Xvfb), on the test driver (lavapipe) with the validation layer on. What it saves, and what its
window shows, must be what `vkray render` renders for the same view, bit for bit.

Run by CTest (tests/CMakeLists.txt) with VKRAY_EXECUTABLE, VKRAY_SCENE_DIR and VKRAY_SHADER_DIR set.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

VKRAY = os.environ["VKRAY_EXECUTABLE"]
SCENES = Path(os.environ["VKRAY_SCENE_DIR"])
SHADERS = Path(os.environ["VKRAY_SHADER_DIR"])


# ---- The display and the viewer ------------------------------------------------------------------

@pytest.fixture(scope="module")
def display():
    """A virtual X display of its own (Xvfb picks a free number and writes it to a pipe)."""
    read, write = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                            pass_fds=[write], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    number = b""
    with os.fdopen(read, "rb") as pipe:
        while not number.endswith(b"\n"):
            chunk = pipe.read(1)
            if not chunk:
                break
            number += chunk
    assert number.strip(), "Xvfb did not start"
    yield ":" + number.decode().strip()
    xvfb.terminate()
    xvfb.wait(10)


class Viewer:
    """A running `vkray view`, its output read line by line on a thread."""

    def __init__(self, display, args, cwd, env=None):
        environment = dict(os.environ, DISPLAY=display, **(env or {}))
        self.process = subprocess.Popen([VKRAY, "view", *args], cwd=cwd, env=environment, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True)
        self.lines = []
        self.display = display
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        # Xvfb resets itself whenever its last client leaves, and refuses connections meanwhile: an
        # xdotool call that ended while vkray was connecting failed its window ("Failed to open
        # display"). vkray prints the device once its window is open; from then on its connection
        # holds the server.
        self.wait_line(r"^vkray: device ")
        self.window = self._find_window()
        # Ready: the shaders compiled and the files watched (the window opens before).
        self.wait_line(r"^vkray: viewing ")

    def _read(self):
        for line in self.process.stdout:
            self.lines.append(line.rstrip("\n"))

    def _xdotool(self, *args):
        return subprocess.run(["xdotool", *args], env=dict(os.environ, DISPLAY=self.display), capture_output=True,
                              text=True, timeout=60)

    def _find_window(self):
        deadline = time.time() + 60
        while time.time() < deadline:
            found = self._xdotool("search", "--name", "^vkray view")
            if found.returncode == 0 and found.stdout.split():
                return found.stdout.split()[0]
            assert self.process.poll() is None, "vkray view exited: " + self.output()
            time.sleep(0.1)
        raise AssertionError("no vkray view window within 60 s: " + self.output())

    def output(self):
        return "\n".join(self.lines)

    def keys(self, *names, delay_ms=30):
        result = self._xdotool("key", "--window", self.window, "--delay", str(delay_ms), *names)
        assert result.returncode == 0, result.stderr

    def mouse(self, *commands):
        """xdotool mouse commands, the window focused first (mousemove is relative to the window)."""
        result = self._xdotool("mousemove", "--window", self.window, *commands)
        assert result.returncode == 0, result.stderr

    def wait_line(self, pattern, after=0, timeout=60):
        deadline = time.time() + timeout
        while time.time() < deadline:
            for index, line in enumerate(self.lines[after:], after):
                if re.search(pattern, line):
                    return index, line
            assert self.process.poll() is None or any(re.search(pattern, l) for l in self.lines[after:]), \
                "vkray view exited before printing /" + pattern + "/:\n" + self.output()
            time.sleep(0.05)
        raise AssertionError("no line /" + pattern + "/ within " + str(timeout) + " s:\n" + self.output())

    def close(self):
        if self.process.poll() is None:
            closed = self._xdotool("key", "--window", self.window, "Escape")
            # The window may have gone by itself meanwhile (--exit-when-done).
            assert closed.returncode == 0 or self.process.wait(10) is not None, closed.stderr
        code = self.process.wait(60)
        self._reader.join(10)
        return code


def assert_no_validation_messages(viewer):
    for message in ("validation error", "validation warning", "validation message"):
        assert message not in viewer.output(), viewer.output()


# ---- Images --------------------------------------------------------------------------------------

def read_pfm(path):
    data = Path(path).read_bytes()
    header, rest = data.split(b"\n", 1)
    size, rest = rest.split(b"\n", 1)
    scale, pixels = rest.split(b"\n", 1)
    width, height = map(int, size.split())
    assert header == b"PF" and float(scale) < 0
    return np.frombuffer(pixels, "<f4").reshape(height, width, 3)[::-1]


def read_png(path):
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    pixels = image.read_image("uint8")
    image.close()
    return pixels[:, :, :3]


def restarts(log):
    """How many accumulations the viewer has started, by its frame log."""
    lines = log.read_text().splitlines() if log.exists() else []
    return json.loads(lines[-1])["restarts"] if lines else 0


def wait_until_done(log, after_restarts=0, timeout=120):
    """Until the frame log's last frame, of an accumulation started after `after_restarts` of them,
    has every sample, and no frame has come since for a while."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        lines = log.read_text().splitlines() if log.exists() else []
        if lines:
            last = json.loads(lines[-1])
            if last["samples"] == last["target"] > 0 and last["restarts"] > after_restarts:
                time.sleep(0.5)
                if log.read_text().splitlines()[-1] == lines[-1]:
                    return
        time.sleep(0.1)
    raise AssertionError("the accumulation did not finish within " + str(timeout) + " s")


def render(scene, out, *args):
    result = subprocess.run([VKRAY, "render", str(scene), "-o", str(out), "-q", *args], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr


def scene_with_view(scene, view_line, out):
    """The scene file with the camera, first light and integrator of a `vkray: view:` line."""
    camera = json.loads("{" + re.search(r'("camera": \{[^}]*\})', view_line).group(1) + "}")["camera"]
    data = json.loads(Path(scene).read_text())
    data["camera"] = camera
    light = re.search(r"first light at (\[[^\]]*\])", view_line)
    if light:
        data["lights"][0]["position"] = json.loads(light.group(1))
    integrator = re.search(r"integrator (\w+)", view_line).group(1)
    data.setdefault("integrator", {})["type"] = integrator
    # The scene's meshes stay where they are: paths in a scene file are relative to its folder.
    Path(out).write_text(json.dumps(data))
    return out


# ---- Tests ---------------------------------------------------------------------------------------

def test_without_a_display_it_says_so_and_names_the_headless_commands(tmp_path):
    environment = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    result = subprocess.run([VKRAY, "view", str(SCENES / "cornell.json")], cwd=tmp_path, env=environment,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 3, result.stderr
    assert "no display" in result.stderr
    assert "vkray render" in result.stderr and "vkray watch" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("scene, spp", [("cornell.json", 4), ("cornell-path.json", 6)])
def test_accumulation_ends_at_the_render_bit_for_bit(display, tmp_path, scene, spp):
    size = ["--width", "120", "--height", "88", "--spp", str(spp)]
    viewer = Viewer(display, [str(SCENES / scene), *size, "-o", "view.pfm", "--exit-when-done", "--validate"], tmp_path)
    assert viewer.process.wait(120) == 0, viewer.output()
    viewer.close()
    assert_no_validation_messages(viewer)
    render(SCENES / scene, tmp_path / "render.pfm", *size)
    assert (tmp_path / "view.pfm").read_bytes() == (tmp_path / "render.pfm").read_bytes()


def read_exr_channels(path):
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    names = list(image.spec().channelnames)
    pixels = image.read_image("float")
    image.close()
    return names, pixels


def test_first_hit_passes_accumulate_into_the_renders_exr(display, tmp_path):
    size = ["--width", "72", "--height", "48", "--spp", "4"]
    passes = ["--aov", "albedo,normal,position,depth,object", "--exr-float"]
    viewer = Viewer(display, [str(SCENES / "depth-of-field.json"), *size, *passes, "-o", "view.exr", "--exit-when-done",
                              "--validate"], tmp_path)
    assert viewer.process.wait(120) == 0, viewer.output()
    viewer.close()
    assert_no_validation_messages(viewer)
    render(SCENES / "depth-of-field.json", tmp_path / "render.exr", *size, *passes)
    view_names, view_pixels = read_exr_channels(tmp_path / "view.exr")
    render_names, render_pixels = read_exr_channels(tmp_path / "render.exr")
    assert view_names == render_names and "depth.Z" in view_names
    assert np.array_equal(view_pixels, render_pixels, equal_nan=True)


def test_the_render_follows_the_windows_size(display, tmp_path):
    log = tmp_path / "frames.jsonl"
    viewer = Viewer(display, [str(SCENES / "cornell.json"), "--width", "64", "--height", "48", "--spp", "2", "-o",
                              "view.pfm", "--frame-log", str(log), "--validate"], tmp_path)
    result = viewer._xdotool("windowsize", viewer.window, "80", "40")
    assert result.returncode == 0, result.stderr
    deadline = time.time() + 60
    while time.time() < deadline:
        lines = log.read_text().splitlines() if log.exists() else []
        if lines and json.loads(lines[-1])["width"] == 80 and json.loads(lines[-1])["samples"] == 2:
            break
        time.sleep(0.1)
    viewer.keys("p")
    viewer.wait_line(r"wrote view\.pfm \(2 of 2 samples\)")
    assert viewer.close() == 0, viewer.output()
    assert_no_validation_messages(viewer)
    assert read_pfm(tmp_path / "view.pfm").shape == (40, 80, 3)
    render(SCENES / "cornell.json", tmp_path / "render.pfm", "--width", "80", "--height", "40", "--spp", "2")
    assert (tmp_path / "view.pfm").read_bytes() == (tmp_path / "render.pfm").read_bytes()


def start_on_a_copy(display, tmp_path, scene_name, size):
    """The viewer on a copy of the shipped scenes (a scene of the view is written beside them), its
    first accumulation done. Returns the viewer, the scene file, the frame log and its restarts."""
    shutil.copytree(SCENES, tmp_path / "scenes")
    scene = tmp_path / "scenes" / scene_name
    log = tmp_path / "frames.jsonl"
    viewer = Viewer(display, [str(scene), *size, "-o", "view.pfm", "--validate", "--frame-log", str(log)], tmp_path)
    wait_until_done(log)
    return viewer, scene, log, restarts(log)


def save_and_close(viewer, spp):
    """P (the image, done) and F12 (the window), then Esc; returns the `vkray: view:` line."""
    viewer.keys("p")
    viewer.wait_line(r"wrote view\.pfm \(%d of %d samples\)" % (spp, spp))
    _, view = viewer.wait_line(r"^vkray: view: ")
    viewer.keys("F12")
    viewer.wait_line(r"wrote .*view-window\.png")
    assert viewer.close() == 0, viewer.output()
    assert_no_validation_messages(viewer)
    return view


def test_a_scripted_session_saves_what_render_renders_of_the_same_view(display, tmp_path):
    # The lab's scene: keys move the camera and the light, the mouse orbits and zooms, I switches to
    # the path tracer; then the overlay is hidden, and the image and the window saved. The saved image
    # is `vkray render`'s of the view the viewer prints, and the window shows exactly its PNG.
    size = ["--width", "96", "--height", "80", "--spp", "4"]
    viewer, scene, log, before = start_on_a_copy(display, tmp_path, "cornell.json", size)
    viewer.keys("Up", "Up", "Right", "w", "w", "d", "q")
    viewer.mouse("40", "30", "mousedown", "1", "mousemove_relative", "--", "12", "-6", "mouseup", "1")
    viewer.mouse("48", "40", "click", "4")  # the wheel: zoom in a notch
    viewer.keys("i", "Tab")
    wait_until_done(log, before)
    # The window as shown is under the PNG's display transform (the default: clamp and sRGB).
    view = save_and_close(viewer, 4)
    assert "integrator path" in view

    scene_with_view(scene, view, tmp_path / "scenes" / "viewed.json")
    render(tmp_path / "scenes" / "viewed.json", tmp_path / "render.pfm", *size)
    render(tmp_path / "scenes" / "viewed.json", tmp_path / "render.png", *size)
    render(scene, tmp_path / "start.pfm", *size)
    assert (tmp_path / "view.pfm").read_bytes() == (tmp_path / "render.pfm").read_bytes()
    assert not np.array_equal(read_pfm(tmp_path / "view.pfm"), read_pfm(tmp_path / "start.pfm")), "nothing moved"
    window = read_png(tmp_path / "view-window.png")
    assert window.shape == (80, 96, 3)
    assert np.array_equal(window, read_png(tmp_path / "render.png"))


def test_a_shader_edit_reloads_in_place_and_a_broken_one_keeps_the_last_image(display, tmp_path):
    shaders = tmp_path / "shaders"
    shutil.copytree(SHADERS, shaders)
    size = ["--width", "64", "--height", "48", "--spp", "1"]
    log = tmp_path / "frames.jsonl"
    viewer = Viewer(display, [str(SCENES / "cornell.json"), *size, "--shader-dir", str(shaders), "-o", "view.pfm",
                              "--validate", "--frame-log", str(log)], tmp_path)
    shade = shaders / "direct.glsl"
    original = shade.read_text()
    # A syntax error: reported as file:line, and the window goes on.
    shade.write_text(original + "\nthis is not glsl\n")
    index, _ = viewer.wait_line(r"direct\.glsl:\d+: .*error")
    viewer.wait_line(r"reload: .*shader has errors; the last good image stays", after=index)
    # Every direct sample made red: the window's next image is.
    red = original.replace("vec3 direct_radiance(", "vec3 direct_radiance_unused(", 1)
    assert red != original
    red += "\nvec3 direct_radiance(Ray ray, inout uint stream, inout uint rays) { return vec3(1.0, 0.0, 0.0); }\n"
    before = restarts(log)
    shade.write_text(red)
    index, _ = viewer.wait_line(r"reload: compile", after=index + 1)
    wait_until_done(log, before)
    viewer.keys("p")
    viewer.wait_line(r"wrote view\.pfm \(1 of 1 samples\)", after=index)
    assert viewer.close() == 0, viewer.output()
    assert_no_validation_messages(viewer)
    # Every pixel the edited shader's red (in the units the shader works in: the host scales them).
    image = read_pfm(tmp_path / "view.pfm").reshape(-1, 3)
    assert np.all(image == image[0]) and image[0][0] > 0 and image[0][1] == 0 and image[0][2] == 0, image[0]


def test_a_thousand_resets_leave_memory_flat(display, tmp_path):
    # R starts the accumulation again: a new accumulation's buffers, descriptors and commands each
    # time. Anonymous memory only, without Mesa's shader cache and with glibc's mmap threshold fixed,
    # as the watch leak test measures (tests/watch_test.cpp says why).
    log = tmp_path / "frames.jsonl"
    viewer = Viewer(display, [str(SCENES / "cornell.json"), "--width", "64", "--height", "64", "--spp", "1",
                              "--frame-log", str(log)], tmp_path,
                    env={"MESA_SHADER_CACHE_DISABLE": "true", "MALLOC_MMAP_THRESHOLD_": "131072"})

    def restarts():
        lines = log.read_text().splitlines() if log.exists() else []
        return json.loads(lines[-1])["restarts"] if lines else 0

    def anon_kib():
        for line in Path(f"/proc/{viewer.process.pid}/status").read_text().splitlines():
            if line.startswith("RssAnon:"):
                return int(line.split()[1])
        raise AssertionError("no RssAnon")

    def press_until(count):
        while restarts() < count:
            viewer.keys(*(["r"] * 50), delay_ms=12)
        return anon_kib()

    after_100 = press_until(100)
    after_1100 = press_until(1100)
    assert viewer.close() == 0, viewer.output()
    assert after_1100 - after_100 <= 4 * 1024, f"anonymous memory grew from {after_100} to {after_1100} KiB"


def test_display_keys_and_a_focus_click_show_what_render_writes(display, tmp_path):
    # The thin-lens scene: a middle click focuses where it points, + + raises the exposure a stop,
    # T picks ACES; the window then shows exactly `vkray render`'s PNG of the printed view with
    # --exposure 1 --tonemap aces.
    size = ["--width", "96", "--height", "64", "--spp", "2"]
    viewer, scene, log, before = start_on_a_copy(display, tmp_path, "depth-of-field.json", size)
    viewer.mouse("24", "34", "click", "2")  # a sphere behind the one in focus
    viewer.wait_line(r"^vkray: focus distance 9\.")
    viewer.keys("equal", "equal", "t", "Tab")
    wait_until_done(log, before)
    view = save_and_close(viewer, 2)
    assert "focus_distance" in view
    scene_with_view(scene, view, tmp_path / "scenes" / "viewed.json")
    render(tmp_path / "scenes" / "viewed.json", tmp_path / "render.pfm", *size)
    assert (tmp_path / "view.pfm").read_bytes() == (tmp_path / "render.pfm").read_bytes()
    render(tmp_path / "scenes" / "viewed.json", tmp_path / "render.png", *size, "--exposure", "1", "--tonemap", "aces")
    assert np.array_equal(read_png(tmp_path / "view-window.png"), read_png(tmp_path / "render.png"))
