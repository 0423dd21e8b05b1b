"""Ctrl-C during a render from Python: KeyboardInterrupt within a fraction of a second, on every
thread that renders."""

import os
import signal
import subprocess
import sys
import time

import pytest

SCRIPT = """
import sys, time, vkray
r = vkray.Renderer()
r.render(sys.argv[1], width=16, height=16)  # compiled before the long render
print("rendering", flush=True)
try:
    r.render(sys.argv[1], width=1024, height=1024, spp=4096)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    r.render(sys.argv[1], width=16, height=16)  # the renderer goes on working
    print("rendered again", flush=True)
    sys.exit(0)
sys.exit("not interrupted")
"""


def test_ctrl_c_raises_keyboard_interrupt_promptly(scenes):
    child = subprocess.Popen([sys.executable, "-c", SCRIPT, str(scenes / "cornell.json")], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=os.environ)
    try:
        assert child.stdout.readline().strip() == "rendering"
        time.sleep(1.0)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        assert child.stdout.readline().strip() == "interrupted"
        waited = time.monotonic() - sent
        out, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == 0, err
    assert "rendered again" in out
    assert waited < 1.5, f"KeyboardInterrupt {waited:.2f} s after SIGINT"


# Threads render while the main thread waits in join(), sleeps, or renders too; SIGINT with Python's
# default handler stops every render, each raising KeyboardInterrupt, and renders started afterwards run.
THREADS = """
import signal, sys, threading, time, vkray
SCENE, MAIN = sys.argv[1], sys.argv[2]
vkray.render(SCENE, width=16, height=16)
outcomes, started = [], threading.Semaphore(0)

def work(renderer):
    started.release()
    try:
        renderer(SCENE, width=1024, height=1024, spp=4096)
        outcomes.append("finished")
    except KeyboardInterrupt:
        outcomes.append("interrupted")

gpu = vkray.Renderer()
threads = [threading.Thread(target=work, args=(gpu.render,)),
           threading.Thread(target=work, args=(lambda s, **k: vkray.render(s, renderer="cpu", threads=1, **k),))]
for t in threads:
    t.start()
for t in threads:
    started.acquire()
time.sleep(0.5)
print("rendering", flush=True)
try:
    if MAIN == "join":
        for t in threads:
            t.join()
    elif MAIN == "sleep":
        time.sleep(600)
    else:
        vkray.render(SCENE, width=1024, height=1024, spp=4096)
    sys.exit("the main thread was not interrupted")
except KeyboardInterrupt:
    pass
for t in threads:
    while t.is_alive():  # not join(): a join that a KeyboardInterrupt cut short may return early
        time.sleep(0.05)
print(*outcomes, flush=True)
print(gpu.render(SCENE, width=16, height=16).shape, vkray.render(SCENE, width=16, height=16, renderer="cpu").shape, flush=True)
"""


def interrupt(script: str, *args: str, after: float = 0.0) -> subprocess.CompletedProcess:
    """Runs `script`, sends it SIGINT `after` seconds after it prints "rendering", and waits for it: a
    hang fails (a minute; each long render of these scripts takes many on lavapipe)."""
    child = subprocess.Popen([sys.executable, "-c", script, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, env=os.environ)
    try:
        assert child.stdout.readline().strip() == "rendering"
        time.sleep(after)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
            child.communicate()
    return subprocess.CompletedProcess(child.args, child.returncode, out, err)


@pytest.mark.parametrize("main", ["join", "sleep", "render"])
def test_ctrl_c_stops_the_renders_of_every_thread(scenes, main):
    result = interrupt(THREADS, str(scenes / "cornell.json"), main)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == ["interrupted interrupted", "(16, 16, 3) (16, 16, 3)"], result.stderr


# A program that handles SIGINT itself decides what Ctrl-C means: its renders go on.
OWN_HANDLER = """
import signal, sys, threading, vkray
SCENE = sys.argv[1]
vkray.render(SCENE, width=16, height=16)
caught = threading.Event()
signal.signal(signal.SIGINT, lambda *_: caught.set())
failed = []

def work():
    try:
        while not caught.is_set():  # a render is in flight whenever the signal comes
            vkray.render(SCENE, width=64, height=64, renderer="cpu", threads=1)
    except BaseException as error:
        failed.append(repr(error))

thread = threading.Thread(target=work)
thread.start()
print("rendering", flush=True)
caught.wait(60)
thread.join()
print(failed or "went on", flush=True)
"""


def test_a_programs_own_sigint_handler_leaves_renders_running(scenes):
    result = interrupt(OWN_HANDLER, str(scenes / "cornell.json"), after=0.5)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "went on", result.stderr
