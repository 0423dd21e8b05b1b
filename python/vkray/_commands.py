"""What the package's commands (python3 -m vkray.farm, python3 -m vkray.denoise) share: the image
options `vkray render` has, and how an error ends one, with one line on stderr and the exit code of
its kind, in `vkray render`'s classes."""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Any, Optional


def add_image_options(parser: Any) -> None:
    """--width, --height, --spp and --seed, as text (read later by the library, as `vkray render`
    reads its flags), on an argparse parser or argument group."""
    parser.add_argument("--width", metavar="W", help="image width in pixels (default: the scene's)")
    parser.add_argument("--height", metavar="H", help="image height in pixels (default: the scene's)")
    parser.add_argument("--spp", metavar="N", help="samples per pixel (default: the scene's)")
    parser.add_argument("--seed", metavar="S", help="sample streams (default: the scene's)")


def run_command(prog: str, run: Callable[[], int], exit_codes: Sequence[tuple[type, int]],
                interrupted: Callable[[], bool] = lambda: False) -> int:
    """``run()``'s exit code; for an exception, "PROG: error: MESSAGE" on stderr and the code
    ``exit_codes`` gives its kind (first match), or 3 for one it does not list, named with its type
    (a cluster's or a library's own failure); 130, "nothing written", for Ctrl-C, and for any
    exception once ``interrupted()`` says a signal stopped the command."""
    try:
        return run()
    except KeyboardInterrupt:
        print(f"{prog}: interrupted; nothing written", file=sys.stderr)
        return 130
    except Exception as e:
        if interrupted():
            print(f"{prog}: interrupted; nothing written", file=sys.stderr)
            return 130
        code: Optional[int] = next((code for kind, code in exit_codes if isinstance(e, kind)), None)
        own = code is not None and not isinstance(e, MemoryError)
        print(f"{prog}: error: {e if own else f'{type(e).__name__}: {e}'}", file=sys.stderr)
        return 3 if code is None else code
