"""How a Python program may end while vkray renders, and processes made by fork: each ending keeps its
exit code and ends without SIGABRT, and a forked child renders (or says what to do instead) rather
than hanging. Each case runs in a process of its own, under a timeout, so that a hang fails the test
rather than hanging it."""

import multiprocessing
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import vkray

# A render that would take minutes on lavapipe: whatever ends the program ends it mid-render.
LONG = "width=1024, height=1024, spp=4096"
SMALL = dict(width=32, height=24)
TIMEOUT = 120  # a hang fails the test; no assertion is made about speed


def run_program(body: str, scene) -> subprocess.CompletedProcess:
    program = textwrap.dedent(f"""
        import sys, threading, time, types, vkray
        SCENE = {str(scene)!r}
        # A teardown that takes a while, as a finalizer doing I/O does: the end of the interpreter then
        # lasts longer than the module's 50 ms polls of a render, so every thread whose render is in
        # flight comes back for the GIL while it ends, whatever the timing.
        class SlowTeardown:
            def __del__(self, sleep=time.sleep):
                sleep(0.2)
        sys.modules["slow_teardown"] = types.ModuleType("slow_teardown")
        sys.modules["slow_teardown"].finalizer = SlowTeardown()  # destroyed as the modules are
        vkray.render(SCENE, width=16, height=16)  # the device opened and the shaders compiled once
        def render_long():
            vkray.render(SCENE, {LONG})
        def render_long_cpu():
            vkray.render(SCENE, {LONG}, renderer="cpu", threads=2)
        renders = 0
        def start_rendering(target=render_long, daemon=True):
            # Returns once the thread's render is in flight (or over), as the module counts them.
            global renders
            renders += 1
            ended = threading.Event()
            def work():
                try:
                    target()
                finally:
                    ended.set()
            threading.Thread(target=work, daemon=daemon).start()
            deadline = time.monotonic() + 60
            while vkray._vkray._calls_in_flight() < renders and not ended.is_set():
                if time.monotonic() > deadline:
                    sys.exit("the render did not start")
                time.sleep(0.005)
    """) + textwrap.dedent(body)
    return subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=TIMEOUT)


def expect_clean_end(result: subprocess.CompletedProcess, code: int) -> None:
    assert result.returncode != -signal.SIGABRT and "terminate called" not in result.stderr, result.stderr
    assert result.returncode == code, result.stderr


@pytest.mark.parametrize("target", ["render_long", "render_long_cpu"])
def test_the_main_thread_ends_normally_while_a_daemon_thread_renders(scenes, target):
    result = run_program(f"start_rendering({target})\nprint('leaving', flush=True)\n", scenes / "cornell.json")
    expect_clean_end(result, 0)
    assert result.stdout == "leaving\n"


def test_sys_exit_keeps_its_code_while_a_daemon_thread_renders(scenes):
    expect_clean_end(run_program("start_rendering()\nsys.exit(7)\n", scenes / "cornell.json"), 7)


def test_an_uncaught_exception_keeps_exit_1_and_its_traceback(scenes):
    result = run_program("start_rendering()\nraise ValueError('the main thread failed')\n", scenes / "cornell.json")
    expect_clean_end(result, 1)
    assert "Traceback" in result.stderr and "ValueError: the main thread failed" in result.stderr


def test_daemon_threads_waiting_for_a_renderer_or_starting_a_render_at_exit(scenes):
    # One thread renders on a shared renderer, another waits for it; a third keeps starting renders.
    result = run_program("""
        shared = vkray.Renderer()
        def on_shared():
            shared.render(SCENE, width=1024, height=1024, spp=4096)
        def again_and_again():
            while True:
                try:
                    vkray.render(SCENE, width=64, height=64, renderer="cpu", threads=1)
                except KeyboardInterrupt:
                    pass
        start_rendering(on_shared)
        start_rendering(on_shared)
        start_rendering(again_and_again)
        print("leaving", flush=True)
    """, scenes / "cornell.json")
    expect_clean_end(result, 0)


def test_the_program_waits_for_a_non_daemon_thread_to_finish_its_render(scenes):
    result = run_program("""
        def short():
            image = vkray.render(SCENE, width=64, height=64, spp=16)
            print("rendered", image.shape, flush=True)
        start_rendering(short, daemon=False)
        sys.exit(5)
    """, scenes / "cornell.json")
    expect_clean_end(result, 5)
    assert "rendered (64, 64, 3)" in result.stdout


# ---- fork ------------------------------------------------------------------------------------------

def render_in_child(args):
    scene, renderer = args
    return vkray.render(scene, renderer=renderer, **SMALL)


def test_forked_children_render_after_the_parent_did(scenes):
    # bunny.json: a BVH built with oneTBB's threads in the parent and again in each child.
    scene = str(scenes / "bunny.json")
    expected = {r: vkray.render(scene, renderer=r, **SMALL) for r in ("gpu", "cpu")}
    with vkray.Renderer() as kept_open:  # a device open in the parent at the fork
        kept_open.render(scene, **SMALL)
        with multiprocessing.get_context("fork").Pool(2) as pool:
            try:
                images = pool.map_async(render_in_child, [(scene, "gpu"), (scene, "cpu"), (scene, "gpu")]).get(timeout=TIMEOUT)
            finally:
                pool.terminate()
    for image, renderer in zip(images, ("gpu", "cpu", "gpu")):
        assert np.array_equal(image, expected[renderer]), renderer


# What a forked child inherits: set before the fork.
inherited = {}


def use_the_parents_renderer(_) -> str:
    renderer = inherited.pop("renderer")
    try:
        renderer.render(inherited["scene"], **SMALL)
    except vkray.UsageError as error:
        message = str(error)
    else:
        message = "rendered"
    del renderer  # the last reference: dropping it must not wait for the parent's device either
    return message


def test_a_renderer_opened_before_fork_says_what_to_do_in_the_child(scenes):
    inherited["scene"] = str(scenes / "cornell.json")
    with vkray.Renderer() as renderer:
        renderer.render(inherited["scene"], **SMALL)
        inherited["renderer"] = renderer
        try:
            with multiprocessing.get_context("fork").Pool(1) as pool:
                try:
                    message = pool.apply_async(use_the_parents_renderer, (None,)).get(timeout=TIMEOUT)
                finally:
                    pool.terminate()
        finally:
            inherited.clear()
        assert "fork()" in message and "'spawn'" in message, message
        assert renderer.render(str(scenes / "cornell.json"), **SMALL).shape == (24, 32, 3)  # still the parent's


def test_a_forked_child_renders_and_exits_through_the_interpreter(scenes):
    # os.fork() rather than multiprocessing, whose children leave with os._exit(): this child runs
    # atexit, finalizes and runs the C library's exit handlers (the driver's among them).
    result = run_program("""
        import os
        expected = vkray.render(SCENE, width=32, height=24)
        pid = os.fork()
        if pid == 0:
            same = (vkray.render(SCENE, width=32, height=24) == expected).all()
            sys.exit(9 if same else 8)
        for _ in range(1000):
            ended, status = os.waitpid(pid, os.WNOHANG)
            if ended:
                sys.exit(os.waitstatus_to_exitcode(status))
            time.sleep(0.1)
        os.kill(pid, 9)
        sys.exit("the child hung")
    """, scenes / "cornell.json")
    expect_clean_end(result, 9)
