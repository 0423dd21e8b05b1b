"""Ctrl-C during a render from Python: KeyboardInterrupt within a fraction of a second."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

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
