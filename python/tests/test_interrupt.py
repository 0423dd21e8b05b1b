"""Ctrl-C during a render from Python: KeyboardInterrupt within a fraction of a second, on every
thread that renders."""

import os
import signal
import subprocess
import sys
import time

import pytest

# Prints "rendering" once `count` calls into the library are in flight, from a thread of its own. A
# stop request that finds nothing in flight is forgotten (base/interrupt.h), so a test sends SIGINT
# only after that line: a render that started later would not be stopped.
REPORT_WHEN_RENDERING = """
import threading, time, vkray

def report_when_rendering(count):
    def wait():
        deadline = time.monotonic() + 60
        while vkray._vkray._calls_in_flight() < count:
            if time.monotonic() > deadline:
                print(f"{vkray._vkray._calls_in_flight()} of {count} renders started", flush=True)
                return
            time.sleep(0.005)
        print("rendering", flush=True)
    threading.Thread(target=wait, daemon=True).start()
"""

SCRIPT = REPORT_WHEN_RENDERING + """
import sys
r = vkray.Renderer()
r.render(sys.argv[1], width=16, height=16)  # compiled before the long render
report_when_rendering(1)
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
# The main thread waits in slices: CPython runs a signal's handler when a wait ends, so a signal that
# lands just before a wait begins would otherwise be handled only when the whole wait is over.
THREADS = REPORT_WHEN_RENDERING + """
import queue, sys
SCENE, MAIN = sys.argv[1], sys.argv[2]
vkray.render(SCENE, width=16, height=16)
go, outcomes = threading.Event(), queue.Queue()

def work(renderer):
    go.wait()  # once the main thread is inside its try: every KeyboardInterrupt it gets is caught
    try:
        renderer(SCENE, width=1024, height=1024, spp=4096)
        outcomes.put("finished")
    except KeyboardInterrupt:
        outcomes.put("interrupted")

gpu = vkray.Renderer()
threads = [threading.Thread(target=work, args=(gpu.render,)),
           threading.Thread(target=work, args=(lambda s, **k: vkray.render(s, renderer="cpu", threads=1, **k),))]
for t in threads:
    t.start()
report_when_rendering(len(threads) + (MAIN == "render"))  # the main thread's render too
try:
    go.set()
    if MAIN == "join":
        while True:
            for t in threads:
                t.join(0.1)
    elif MAIN == "sleep":
        while True:
            time.sleep(0.1)
    else:
        vkray.render(SCENE, width=1024, height=1024, spp=4096)
    sys.exit("the main thread was not interrupted")
except KeyboardInterrupt:
    pass
# From the threads themselves: after a join that a KeyboardInterrupt cut short, CPython may take a
# thread that still runs for ended.
print(*(outcomes.get(timeout=60) for _ in threads), flush=True)
print(gpu.render(SCENE, width=16, height=16).shape, vkray.render(SCENE, width=16, height=16, renderer="cpu").shape, flush=True)
"""


def interrupt(script: str, *args: str, sent: signal.Signals = signal.SIGINT) -> subprocess.CompletedProcess:
    """Runs `script`, sends it SIGINT (or `sent`) once it prints "rendering", and waits for it: a hang
    fails (a minute; each long render of these scripts takes many on lavapipe)."""
    child = subprocess.Popen([sys.executable, "-c", script, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, env=os.environ)
    try:
        assert child.stdout.readline().strip() == "rendering"
        child.send_signal(sent)
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
OWN_HANDLER = REPORT_WHEN_RENDERING + """
import signal, sys
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
report_when_rendering(1)
while not caught.is_set():  # in slices, as in THREADS
    time.sleep(0.05)
thread.join()
print(failed or "went on", flush=True)
"""


def test_a_programs_own_sigint_handler_leaves_renders_running(scenes):
    result = interrupt(OWN_HANDLER, str(scenes / "cornell.json"))
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "went on", result.stderr


# Any exception a signal handler raises while the main thread renders stops that render and is
# raised as itself: a time limit set with SIGALRM works as it does around Python code.
ALARM = REPORT_WHEN_RENDERING + """
import signal, sys
SCENE = sys.argv[1]
r = vkray.Renderer()
r.render(SCENE, width=16, height=16)

def too_long(*_):
    raise TimeoutError("the render took too long")

signal.signal(signal.SIGALRM, too_long)
report_when_rendering(1)
try:
    r.render(SCENE, width=1024, height=1024, spp=4096)
    sys.exit("the render was not stopped")
except TimeoutError as error:
    print(error, flush=True)
print(r.render(SCENE, width=16, height=16).shape, flush=True)
"""


def test_a_signal_handlers_exception_stops_the_main_threads_render(scenes):
    result = interrupt(ALARM, str(scenes / "cornell.json"), sent=signal.SIGALRM)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == ["the render took too long", "(16, 16, 3)"], result.stderr
