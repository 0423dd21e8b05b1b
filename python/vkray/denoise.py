"""python3 -m vkray.denoise (and the ``vkray-denoise`` command a pip install makes): a render denoised
with Intel Open Image Denoise (``vkray.denoise``), from an image file or from a scene rendered for it.

    python3 -m vkray.denoise INPUT -o OUTPUT [--without-guides] [--quality Q] [--exr-float] [-q]
    python3 -m vkray.denoise SCENE -o OUTPUT [--width W] [--height H] [--spp N] [--seed S]
                             [--aov LIST] [--device D] [--without-guides] [--quality Q] [--exr-float] [-q]

INPUT, a render's .exr or .pfm: its colour denoised, guided by its albedo and normal passes (render
it with ``--aov albedo,normal``); an .exr output keeps every pass the input had. SCENE (.json,
.gltf, .glb): rendered with the guides, then denoised; an .exr output holds the guides and the passes
``--aov`` asks for. OUTPUT is .exr, .pfm or .png, written whole or not at all. Exit codes as
``vkray render``'s: 1 bad input (a file without the guides, an output that cannot be written, pyoidn
not installed), 2 usage, 3 device (OIDN's included), 130 interrupted (Ctrl-C, SIGTERM); on any
failure nothing is written.
"""

from __future__ import annotations

import argparse
import inspect
import sys
import time
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Optional

import vkray
from vkray import _denoise
from vkray._commands import add_image_options, read_image_option, run_command

_SCENE_SUFFIXES = (".json", ".gltf", ".glb")


class _Usage(Exception):
    """A command line that asks for something impossible (exit 2)."""


class _BadInput(Exception):
    """An input that cannot be used as asked (exit 1)."""


_EXIT_CODES = ((_Usage, 2), (_BadInput, 1), (ModuleNotFoundError, 1), (MemoryError, 1), (vkray.SceneError, 1),
               (vkray.UsageError, 2), (vkray.DeviceError, 3), (vkray.InternalError, 70))


def _parser() -> argparse.ArgumentParser:
    # The console script a pip install makes is named as it was run; otherwise the module.
    prog = "vkray-denoise" if Path(sys.argv[0]).name == "vkray-denoise" else "python3 -m vkray.denoise"
    p = argparse.ArgumentParser(prog=prog,
                                description="A render denoised with Intel Open Image Denoise, guided by its albedo "
                                            "and normal passes: from a render's .exr or .pfm, or a scene rendered for it.")
    p.add_argument("input", metavar="INPUT", help="a render's .exr or .pfm, or a scene (.json, .gltf, .glb) to render")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="the denoised image: .exr, .pfm or .png")
    p.add_argument("--without-guides", action="store_true", help="denoise the colour alone, without albedo and normal")
    p.add_argument("--quality", default="high", choices=_denoise.QUALITIES, help="OIDN's quality (default: high)")
    p.add_argument("--exr-float", action="store_true", help="32-bit float channels in an .exr output "
                   "(an .exr input's own precision otherwise)")
    p.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    scene = p.add_argument_group("with a SCENE")
    add_image_options(scene)
    scene.add_argument("--aov", default="", metavar="LIST", help="more first-hit passes for an .exr output, comma-separated")
    scene.add_argument("--device", metavar="D", help="an index or part of a name from `vkray devices`")
    return p


def _log(quiet: bool, line: str) -> None:
    if not quiet:
        print(f"vkray.denoise: {line}", file=sys.stderr)


def run(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    from_scene = Path(args.input).suffix.lower() in _SCENE_SUFFIXES
    if not from_scene:
        given = [f"--{name}" for name in ("width", "height", "spp", "seed", "aov", "device") if getattr(args, name)]
        if given:
            raise _Usage(f"{', '.join(given)}: for a scene to render; {args.input} is an image to denoise")
    extra = [name for name in args.aov.split(",") if name] if from_scene else []
    guides = [] if args.without_guides else list(_denoise.GUIDES)
    written = extra + [g for g in guides if g not in extra]
    exr = Path(args.output).suffix.lower() == ".exr"
    # The output is checked before any work, as `vkray render` checks it (--aov for an output that is
    # not an EXR is refused as it refuses it); OIDN before a render, and an input file before OIDN.
    vkray._vkray._check_output(args.output, written if exr else extra, args.exr_float, False)

    start = time.monotonic()
    if from_scene:
        sizes = {name: read_image_option(name, getattr(args, name)) for name in ("width", "height", "spp", "seed")}
        _denoise._oidn()
        result = vkray.render(args.input, aovs=written, device=args.device, **sizes)
        arrays = result if written else {"color": result}
        exr_float = args.exr_float
        _log(args.quiet, f"rendered {args.input} in {time.monotonic() - start:.2f} s")
    else:
        arrays, full_float = vkray._vkray._read_image(args.input)
        missing = [g for g in guides if g not in arrays]
        if missing:
            has = ", ".join(name for name in arrays if name != "color") or "no passes"
            raise _BadInput(f"{args.input}: has no {' and no '.join(missing)} pass (it has {has}); render it with "
                            "--aov albedo,normal, or denoise without guides (--without-guides)")
        exr_float = args.exr_float or (full_float and Path(args.input).suffix.lower() == ".exr")
    started = time.monotonic()
    denoised = _denoise.denoise(arrays["color"], *(arrays[g] for g in guides), quality=args.quality)
    _log(args.quiet, f"denoised {denoised.shape[1]}x{denoised.shape[0]} in {time.monotonic() - started:.2f} s"
                     f"{' without guides' if not guides else ''}")
    out = dict(arrays, color=denoised) if exr else {"color": denoised}
    vkray._vkray._write_image(args.output, out, exr_float)
    _log(args.quiet, f"wrote {args.output}")
    return 0


def main(argv: Optional[Sequence[str]] = None) -> int:
    return run_command("vkray.denoise", lambda: run(argv), _EXIT_CODES)


class _CallableModule(types.ModuleType):
    """Importing vkray.denoise (the console script does) binds the package's name ``denoise`` to this
    module; calling it still denoises, as ``vkray.denoise(...)`` does everywhere else, with the
    function's signature (``inspect.signature``)."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return _denoise.denoise(*args, **kwargs)


if __name__ == "__main__":
    sys.exit(main())
else:
    sys.modules[__name__].__class__ = _CallableModule
    __signature__ = inspect.signature(_denoise.denoise)
