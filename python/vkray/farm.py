"""One render spread over a Dask cluster: ``python3 -m vkray.farm SCENE -o OUT``.

The image is cut into bands of about equal work (``vkray.bands``, the bands ``vkray render --region
I/N`` renders); each band is a Dask task that renders it on a worker's GPU as a part file, and the
parts come back to this process, which merges them (``vkray.merge``) into OUT: byte for byte the
image a single ``vkray render -o OUT`` gives when the workers share a build and a device type. More
scenes after ``--frames`` are more frames, each its own set of tasks. With ``--denoise`` the parts
hold the albedo and normal passes too, and each merged frame is denoised here, whole (a denoiser looks
across the bands' edges), with Intel Open Image Denoise (``vkray.denoise``): the image
``python3 -m vkray.denoise SCENE -o OUT`` gives.

Without ``--scheduler`` a ``LocalCluster`` of ``--workers`` processes runs here. With one, the tasks
go to that cluster's workers that declare a GPU (``dask worker ADDRESS --resources GPU=1``), one task
per GPU at a time; a worker uses the device named by its ``VKRAY_DEVICE`` variable (an index or part
of a name from ``vkray devices``), or the best one. Workers read the scene by its absolute path, so
it must be on a file system they share (as on a Slurm cluster), and import this package.

A worker that is lost mid-task has its task run again elsewhere (Dask's scheduler does that, up to
``distributed.scheduler.allowed-failures`` times); when no worker with a GPU is left for
``--worker-timeout`` seconds, the job fails. A worker that is still there but makes no progress
(stopped, stuck in a driver, or a much slower GPU) is slow once it has held parts without starting
or finishing one for ``--slow-factor`` times the median time of the finished parts (at least
``--slow-floor`` seconds): the job says so and renders its parts again on the other workers, uses
each part's first result and cancels the rest. A part that fails (a bad scene, a device error) fails
the whole job with vkray's message, and then no output is written: the outputs of all frames are
written only when every part of every frame is in. At the end the job closes its LocalCluster in
bounded time and ends any worker process that does not answer. Exit codes are vkray's: 0 done,
1 bad input (an output that cannot be written included), 2 usage, 3 device or cluster failure,
130 interrupted (Ctrl-C or SIGTERM).

This module is the command line and the order of a job; the job's parts are in private modules:
_farm_worker (the task a worker runs), _farm_cluster (connecting, closing), _farm_parts (submitting
the parts, writing them as they arrive, the watch for slow workers), _farm_outputs (merging the
frames, putting them in place) and _farm_errors (the farm's kinds of failure).
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional, Sequence

import vkray

from . import _denoise
from ._commands import add_image_options, no_interrupts, read_image_option, run_command
from ._farm_cluster import _close, _connect, _gpu_workers, _require_dask
from ._farm_errors import _CannotWrite, _ClusterError, _MissingPackage, _Usage
from ._farm_outputs import _commit, _denoise_frames, _frame_output, _merge_frames
from ._farm_parts import _PART_SUFFIX, _frame_parts, _Job, _Part
from ._farm_worker import _render_part  # noqa: F401  (the task, also as vkray.farm._render_part)

# ---- the command line -----------------------------------------------------------------------------

# The options whose value is an integer, read as `vkray render` reads its flags (_integer).
_INTEGER_OPTIONS = ("--width", "--height", "--spp", "--seed", "--regions", "--workers")
# Those that the library's table of limits holds, by the name `vkray._request` gives them.
_LIMITED = ("width", "height", "spp", "seed")
_MAX_WORKERS = 256


def _number(what: str, low: float, high: float):
    """An argparse type: a number more than `low` and less than `high`."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a {what}") from None
        if not low < value < high:
            raise argparse.ArgumentTypeError(f"{value:g} is not more than {low:g} and less than {high:.0f}")
        return value
    return parse


_seconds = _number("number of seconds", 0, 1e6)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python3 -m vkray.farm",
        description="Render a scene (or frames) as bands of about equal work, as Dask tasks, and merge them.",
        epilog="Exit codes: 0 done, 1 bad input, 2 usage, 3 device or cluster failure, 130 interrupted.")
    p.add_argument("scene", help="scene file (.json, .gltf, .glb), read by every worker at its absolute path")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="the whole image: .exr, .pfm or .png; with --frames, "
                   "frame N goes to OUT with .NNNN before the suffix")
    p.add_argument("--regions", metavar="N",
                   help="bands per frame (default: twice the GPUs the workers declare, at least 2, at most the rows)")
    p.add_argument("--frames", nargs="+", default=[], metavar="SCENE", help="more scenes, rendered as frames 1, 2, ...")
    p.add_argument("--scheduler", metavar="ADDRESS", help="address of a Dask scheduler (tcp://host:8786); default: a LocalCluster here")
    p.add_argument("--workers", default="1", metavar="K",
                   help="LocalCluster worker processes (default 1). Each opens the device VKRAY_DEVICE names, or the "
                        "best one: more than one shares that GPU, which helps only a device that one process "
                        "leaves idle")
    p.add_argument("--worker-timeout", type=_seconds, default=60.0, metavar="SECONDS",
                   help="how long to wait for the scheduler, and for a worker with a GPU when the cluster has none "
                        "(default 60)")
    p.add_argument("--slow-factor", type=_number("number", 1, 1e6), default=4.0, metavar="F",
                   help="a worker that holds parts but has started or finished none for F times the median time of "
                        "the finished parts (and --slow-floor seconds) is slow: its parts are rendered again on other "
                        "workers, and the first result of each is used (default 4)")
    p.add_argument("--slow-floor", type=_seconds, default=10.0, metavar="SECONDS",
                   help="the least time that makes a worker slow, whatever the median (default 10)")
    add_image_options(p)
    p.add_argument("--aov", default="", metavar="LIST", help="first-hit passes for an .exr output, comma-separated")
    p.add_argument("--exr-float", action="store_true", help="32-bit float channels in an .exr output")
    p.add_argument("--denoise", action="store_true",
                   help="denoise each merged frame with Intel Open Image Denoise (pyoidn), guided by its albedo and "
                        "normal passes, which the parts then render too; an .exr output keeps them")
    p.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    return p


def _glued(argv: Sequence[str]) -> list[str]:
    """`argv` with each integer option joined to the word after it ("--width=-x"): argparse takes a
    word that begins with '-' for an option of its own, `vkray render` takes it as the value."""
    out, i = [], 0
    while i < len(argv):
        if argv[i] == "--":
            return out + list(argv[i:])
        glue = argv[i] in _INTEGER_OPTIONS and i + 1 < len(argv)
        out.append(f"{argv[i]}={argv[i + 1]}" if glue else argv[i])
        i += 2 if glue else 1
    return out


def _integer(option: str, text: str, low: int, high: int) -> int:
    """An integer option's value, read by the library as `vkray render` reads its flags
    (ArgumentLimit::read, session/options.h): decimal digits, leading zeros read as decimal, from
    `low` to `high`, refused in the command line's words ("--width: expected an integer from 1 to
    16384, got 0")."""
    try:
        return vkray._vkray._read_integer(option, text, low, high)
    except vkray.UsageError as e:
        raise _Usage(str(e)) from None


def _arguments(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    """The command line, its integers read and checked as `vkray render` reads and checks its flags,
    before anything else: --width, --height, --spp and --seed against the library's table of limits,
    --workers against the farm's own. --regions, whose range is the rows of a frame, is checked once
    the scenes are read."""
    args = _parser().parse_args(_glued(sys.argv[1:] if argv is None else argv))
    for name in _LIMITED:
        setattr(args, name, read_image_option(name, getattr(args, name)))
    args.workers = _integer("--workers", args.workers, 1, _MAX_WORKERS)
    # Its range is the rows of a frame, known once the scenes are read (run()).
    args.regions = None if args.regions is None else _integer("--regions", args.regions, 0, 2**32 - 1)
    return args


def _log(quiet: bool, line: str) -> None:
    if not quiet:
        print(f"vkray.farm: {line}", file=sys.stderr, flush=True)


# ---- the job --------------------------------------------------------------------------------------

def run(argv: Optional[Sequence[str]] = None) -> int:
    args = _arguments(argv)
    _require_dask()
    output = Path(args.output)
    aovs = args.aov.split(",") if args.aov else []
    # The library's own checks of an output, so that the farm refuses what `vkray render -o` refuses,
    # with the same message and exit code.
    vkray._vkray._check_output(output, aovs, args.exr_float, False)
    settings = {"width": args.width, "height": args.height, "spp": args.spp, "seed": args.seed, "aovs": args.aov,
                "exr_float": args.exr_float}
    suffix = _PART_SUFFIX[output.suffix.lower()]
    kept = aovs  # the passes each output holds
    if args.denoise:
        try:
            _denoise._oidn("--denoise")
        except ModuleNotFoundError as e:
            raise _MissingPackage(str(e)) from None
        # The parts render the guides too, at full precision: the denoiser's input is the image a
        # single render gives. An .exr output keeps them.
        rendered_passes = aovs + [guide for guide in _denoise.GUIDES if guide not in aovs]
        kept = rendered_passes if output.suffix.lower() == ".exr" else []
        vkray._vkray._check_output(output, kept, args.exr_float, False)
        settings.update(aovs=",".join(rendered_passes), exr_float=True)
        suffix = ".exr"
    # Every scene read here first, so that a bad one fails before any worker starts.
    scenes = [str(Path(s).resolve()) for s in [args.scene, *args.frames]]
    rows = min(vkray.bands(scene, 1, width=args.width, height=args.height)[0][3] for scene in scenes)
    if args.regions is not None and not 1 <= args.regions <= rows:
        raise _Usage(f"--regions {args.regions}: a frame renders {rows} rows, and a band has at "
                     f"least one row, so 1 to {rows}")

    targets = [_frame_output(output, frame, len(scenes)) for frame in range(len(scenes))]
    for target in targets:
        vkray._vkray._check_output(target, kept, args.exr_float, False)

    client = cluster = folder = workspace = None
    try:
        # The parts go to disk as they arrive (the client holds none for long, however many frames),
        # in a folder beside the output, removed at the end whatever happens.
        try:
            folder = Path(tempfile.mkdtemp(prefix=f".{output.name}.parts-", dir=output.parent))
        except OSError as e:
            raise _CannotWrite(f"{output.parent}: cannot write there ({e.strerror})") from None
        if not args.scheduler:
            # A LocalCluster's workers keep their files in a folder of the job's, removed at the end: a
            # worker that had to be ended leaves nothing behind in Dask's shared dask-worker-space.
            try:
                workspace = Path(tempfile.mkdtemp(prefix="vkray-farm-"))
            except OSError as e:
                raise _ClusterError(f"cannot start the workers: no folder for them in {tempfile.gettempdir()} "
                                    f"({e.strerror})") from None
        client, cluster = _connect(args.scheduler, args.workers, args.worker_timeout, workspace)
        started = time.perf_counter()
        gpus = _gpu_workers(client)
        regions = args.regions if args.regions is not None else min(rows, max(2, 2 * gpus))
        # Each frame's bands computed once, here, for all its parts.
        jobs = []  # (frame, band index, scene, region)
        for frame, scene in enumerate(scenes):
            for index, region in enumerate(vkray.bands(scene, regions, width=args.width, height=args.height)):
                jobs.append((frame, index, scene, region))
        _log(args.quiet, f"{len(jobs)} parts ({len(scenes)} frame{'s' if len(scenes) > 1 else ''} x {regions} bands) on "
                         f"{len(client.scheduler_info()['workers'])} workers with {gpus} GPU{'s' if gpus != 1 else ''},"
                         f" scheduler {client.scheduler.address}")
        job = _Job(client, settings, suffix, folder, slow_factor=args.slow_factor, slow_floor=args.slow_floor,
                   worker_timeout=args.worker_timeout, say=lambda line: _log(args.quiet, line))
        for frame, index, scene, region in jobs:
            job.submit(_Part(frame, index, scene, region))
        job.wait()
        rendered = time.perf_counter() - started
        # Every part is here: now, and only now, the outputs are written, each merged under a name
        # of its own in the parts' folder and then all renamed into place (one file system).
        merged = _merge_frames([_frame_parts(folder, frame, suffix) for frame in range(len(scenes))], folder,
                               suffix if args.denoise else output.suffix)
        if args.denoise:
            merged = _denoise_frames(merged, folder, output.suffix, kept, args.exr_float,
                                     lambda line: _log(args.quiet, line))
        with no_interrupts():
            try:
                _commit(merged, targets, folder)
            except OSError as e:
                raise _CannotWrite(f"cannot put the output in place: {e}") from None
        for target in targets:
            _log(args.quiet, f"wrote {target}")
        merged_in = time.perf_counter() - started - rendered
    finally:
        # A second Ctrl-C or a SIGTERM from a batch system must not leave the parts or the cluster.
        with no_interrupts():
            _close(client, cluster)
            for remove in (folder, workspace):
                if remove is not None:
                    shutil.rmtree(remove, ignore_errors=True)
    _log(args.quiet, f"{len(jobs)} parts rendered in {rendered:.2f} s, merged{' and denoised' if args.denoise else ''} "
                     f"in {merged_in:.2f} s")
    return 0


# ---- exit codes and interruptions -----------------------------------------------------------------

# The exit code of each kind of error, in the command line's classes: 1 bad input (an output that
# cannot be written, a machine without Dask (or pyoidn, for --denoise) or without the host memory
# for the job), 2 usage, 3 device or cluster, 70 a bug of vkray's. Anything else is the cluster's
# (a worker lost too often, KilledWorker): 3.
_EXIT_CODES = ((_Usage, 2), (_CannotWrite, 1), (_MissingPackage, 1), (MemoryError, 1), (_ClusterError, 3),
               (vkray.SceneError, 1), (vkray.UsageError, 2), (vkray.DeviceError, 3), (vkray.InternalError, 70))


def main(argv: Optional[Sequence[str]] = None) -> int:
    # SIGTERM (a batch system's cancel, `kill`) stops the farm as Ctrl-C does: the cluster it
    # started is closed and nothing is written.
    return run_command("vkray.farm", lambda: run(argv), _EXIT_CODES)


if __name__ == "__main__":
    sys.exit(main())
