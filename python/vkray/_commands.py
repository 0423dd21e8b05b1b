"""What the package's commands (python3 -m vkray.farm, python3 -m vkray.denoise) share: the image
options `vkray render` has, and how one ends: on an error, with one line on stderr and the exit code
of its kind, in `vkray render`'s classes; on Ctrl-C or SIGTERM, as `vkray render` does, with 130
and nothing written."""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Optional

# While set, Ctrl-C and SIGTERM are ignored: outputs are being renamed into place (milliseconds), or
# a command's temporary files and processes cleaned up.
_shielded = False

# Set when a signal raised KeyboardInterrupt: whatever the command fails with after that (a
# KeyboardInterrupt raised inside an import comes out as CPython's TypeError) is the interruption.
_interrupted = False


def _interrupt(signum: int, frame: Any) -> None:
    global _interrupted
    if not _shielded:
        _interrupted = True
        raise KeyboardInterrupt


@contextlib.contextmanager
def no_interrupts() -> Iterator[None]:
    """Ctrl-C and SIGTERM wait while this holds (run_command installs the handlers that obey it)."""
    global _shielded
    previous, _shielded = _shielded, True
    try:
        yield
    finally:
        _shielded = previous


def add_image_options(parser: Any) -> None:
    """--width, --height, --spp and --seed, as text (read later by the library, as `vkray render`
    reads its flags), on an argparse parser or argument group."""
    parser.add_argument("--width", metavar="W", help="image width in pixels (default: the scene's)")
    parser.add_argument("--height", metavar="H", help="image height in pixels (default: the scene's)")
    parser.add_argument("--spp", metavar="N", help="samples per pixel (default: the scene's)")
    parser.add_argument("--seed", metavar="S", help="sample streams (default: the scene's)")


def read_image_option(name: str, text: Optional[str]) -> Optional[int]:
    """--width, --height, --spp or --seed (`name`) as add_image_options took it, read and checked as
    `vkray render` reads its flags: against the library's table of limits, a UsageError in its words."""
    from ._vkray import _ARGUMENT_LIMITS, _read_integer
    return None if text is None else _read_integer(f"--{name}", text, *_ARGUMENT_LIMITS[name])


def run_command(prog: str, run: Callable[[], int], exit_codes: Sequence[tuple[type, int]]) -> int:
    """``run()``'s exit code; for an exception, "PROG: error: MESSAGE" on stderr and the code
    ``exit_codes`` gives its kind (first match), or 3 for one it does not list, named with its type
    (a cluster's or a library's own failure); 130, "nothing written", for Ctrl-C and SIGTERM (a batch
    system's cancel, `kill`), which raise KeyboardInterrupt in ``run()`` (on the main thread), and for
    any exception after one."""
    global _interrupted
    _interrupted = False
    # The handlers are this call's: a program that calls main() has its own back afterwards.
    previous = {}
    if threading.current_thread() is threading.main_thread():
        for number in (signal.SIGINT, signal.SIGTERM):
            previous[number] = signal.signal(number, _interrupt)
    try:
        return _ended(prog, run, exit_codes)
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def _ended(prog: str, run: Callable[[], int], exit_codes: Sequence[tuple[type, int]]) -> int:
    try:
        return run()
    except KeyboardInterrupt:
        print(f"{prog}: interrupted; nothing written", file=sys.stderr)
        return 130
    except Exception as e:
        if _interrupted:
            print(f"{prog}: interrupted; nothing written", file=sys.stderr)
            return 130
        code: Optional[int] = next((code for kind, code in exit_codes if isinstance(e, kind)), None)
        own = code is not None and not isinstance(e, MemoryError)
        print(f"{prog}: error: {e if own else f'{type(e).__name__}: {e}'}", file=sys.stderr)
        return 3 if code is None else code
