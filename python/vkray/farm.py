"""One render spread over a Dask cluster: ``python3 -m vkray.farm SCENE -o OUT``.

The image is cut into bands of about equal work (``vkray.bands``, the bands ``vkray render --region
I/N`` renders); each band is a Dask task that renders it on a worker's GPU as a part file, and the
parts come back to this process, which merges them (``vkray.merge``) into OUT: byte for byte the
image a single ``vkray render -o OUT`` gives when the workers share a build and a device type. More
scenes after ``--frames`` are more frames, each its own set of tasks.

Without ``--scheduler`` a ``LocalCluster`` of ``--workers`` processes runs here. With one, the tasks
go to that cluster's workers that declare a GPU (``dask worker ADDRESS --resources GPU=1``), one task
per GPU at a time; a worker uses the device named by its ``VKRAY_DEVICE`` variable (an index or part
of a name from ``vkray devices``), or the best one. Workers read the scene by its absolute path, so
it must be on a file system they share (as on a Slurm cluster), and import this package.

A worker that is lost mid-task has its task run again elsewhere (Dask's scheduler does that, up to
``distributed.scheduler.allowed-failures`` times); when no worker with a GPU is left for
``--worker-timeout`` seconds, the job fails. A part that fails (a bad scene, a device error) fails
the whole job with vkray's message, and then no output is written: the outputs of all frames are
written only when every part of every frame is in. Exit codes are vkray's: 0 done, 1 bad input
(an output that cannot be written included), 2 usage, 3 device or cluster failure, 130 interrupted
(Ctrl-C or SIGTERM).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import importlib.util
import logging
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any, Optional, Sequence

import vkray

# A part's file type for each output type: float parts for every output, so that the merged image is
# the single render's exactly.
_PART_SUFFIX = {".exr": ".exr", ".pfm": ".pfm", ".png": ".pfm"}

# ---- the worker's side ----------------------------------------------------------------------------

# One vkray.Renderer per worker process, kept between its tasks: the device stays open, the shaders
# compiled and the last scene's geometry on the device, so that the next band of the same scene
# uploads only what changed.
_renderer: Optional[vkray.Renderer] = None
_renderer_lock = threading.Lock()


def _worker_name(name: Any) -> str:
    """`dask worker --name` names a worker; a LocalCluster numbers them."""
    return f"worker {name}" if isinstance(name, int) else str(name)


def _render_part(scene: str, region: tuple[int, int, int, int], settings: dict[str, Any],
                 suffix: str) -> dict[str, Any]:
    """A Dask task: renders `region` of `scene` and returns the part file's bytes (and a PFM part's
    record) with what it cost."""
    global _renderer
    import distributed

    start = time.perf_counter()
    with _renderer_lock, tempfile.TemporaryDirectory(prefix="vkray-part-") as folder:
        try:
            if _renderer is None:
                _renderer = vkray.Renderer(os.environ.get("VKRAY_DEVICE") or None)
            part = Path(folder) / f"part{suffix}"
            _renderer.render_to_file(scene, part, region=region, **settings)
        except vkray.DeviceError:
            # A failed device is not used again: the next task on this worker opens it afresh.
            renderer, _renderer = _renderer, None
            if renderer is not None:
                try:
                    renderer.close()
                except vkray.Error:
                    pass
            raise
        record = part.with_name(part.name + ".json")
        result = {
            "data": part.read_bytes(),
            "record": record.read_bytes() if record.exists() else None,
            "stats": dict(_renderer.last_stats or {}),
            "device": _renderer.device,
            "worker": _worker_name(distributed.get_worker().name),
        }
    result["seconds"] = time.perf_counter() - start
    return result


# ---- the client's side ----------------------------------------------------------------------------

def _frame_output(output: Path, frame: int, frames: int) -> Path:
    """OUT for one frame; with several, the frame's number before the suffix: out.exr -> out.0001.exr."""
    return output if frames == 1 else output.with_name(f"{output.stem}.{frame:04d}{output.suffix}")


def _whole(low: int, high: int = 2**32 - 1):
    """An argparse type: a whole number from `low` to `high`."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value} is not from {low} to {high}")
        return value
    return parse


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not 0 < value < 1e6:
        raise argparse.ArgumentTypeError(f"{value} seconds: more than 0, less than 1e6")
    return value


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python3 -m vkray.farm",
        description="Render a scene (or frames) as bands of about equal work, as Dask tasks, and merge them.",
        epilog="Exit codes: 0 done, 1 bad input, 2 usage, 3 device or cluster failure, 130 interrupted.")
    p.add_argument("scene", help="scene file (.json, .gltf, .glb), read by every worker at its absolute path")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="the whole image: .exr, .pfm or .png; with --frames, "
                   "frame N goes to OUT with .NNNN before the suffix")
    p.add_argument("--regions", type=_whole(1), default=None, metavar="N",
                   help="bands per frame (default: twice the GPUs the workers declare, at least 2, at most the rows)")
    p.add_argument("--frames", nargs="+", default=[], metavar="SCENE", help="more scenes, rendered as frames 1, 2, ...")
    p.add_argument("--scheduler", metavar="ADDRESS", help="address of a Dask scheduler (tcp://host:8786); default: a LocalCluster here")
    p.add_argument("--workers", type=_whole(1, 256), default=1, metavar="K",
                   help="LocalCluster worker processes (default 1). Each opens the device VKRAY_DEVICE names, or the "
                        "best one: more than one shares that GPU, which helps only a device that one process "
                        "leaves idle")
    p.add_argument("--worker-timeout", type=_seconds, default=60.0, metavar="SECONDS",
                   help="how long to wait for the scheduler, and for a worker with a GPU when the cluster has none "
                        "(default 60)")
    p.add_argument("--width", type=_whole(1), metavar="W", help="image width in pixels (default: the scene's)")
    p.add_argument("--height", type=_whole(1), metavar="H", help="image height in pixels (default: the scene's)")
    p.add_argument("--spp", type=_whole(1), metavar="N", help="samples per pixel (default: the scene's)")
    p.add_argument("--seed", type=_whole(0), metavar="S", help="sample streams (default: the scene's)")
    p.add_argument("--aov", default="", metavar="LIST", help="first-hit passes for an .exr output, comma-separated")
    p.add_argument("--exr-float", action="store_true", help="32-bit float channels in an .exr output")
    p.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    return p


class _Usage(Exception):
    pass


def _log(quiet: bool, line: str) -> None:
    if not quiet:
        print(f"vkray.farm: {line}", file=sys.stderr, flush=True)


class _MissingDask(Exception):
    """Dask's distributed is not importable by the Python that runs the farm."""


def _require_dask() -> None:
    """Fails before any work when this interpreter lacks Dask's distributed, saying how to get it
    for this interpreter: Debian's python3-distributed serves /usr/bin/python3 only, not a venv,
    pyenv or conda interpreter."""
    if importlib.util.find_spec("distributed") is not None:
        return
    advice = f"install it for this Python: {sys.executable} -m pip install distributed"
    if sys.executable != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
        advice += " (or run the farm with /usr/bin/python3 after apt-get install python3-distributed)"
    elif os.path.exists("/etc/debian_version"):
        advice = "install it: apt-get install python3-distributed (or " + advice + ")"
    raise _MissingDask(f"the farm needs Dask's distributed, which {sys.executable} cannot import; {advice}")


class _CannotWrite(Exception):
    pass


class _ClusterError(Exception):
    """The cluster cannot do the job: no workers, none with a GPU, all of them lost."""


def _gpu_workers(client: Any) -> int:
    return sum(1 for w in client.scheduler_info()["workers"].values() if w.get("resources", {}).get("GPU", 0) >= 1)


def _connect(args: argparse.Namespace):  # -> (Client, cluster or None)
    import distributed

    if args.scheduler:
        import dask

        try:
            # The connection's own timeout (30 s in Dask's configuration) bounds each attempt.
            with dask.config.set({"distributed.comm.timeouts.connect": f"{args.worker_timeout}s"}):
                client = distributed.Client(args.scheduler, timeout=f"{args.worker_timeout}s")
        except OSError as e:
            raise _ClusterError(f"cannot reach the scheduler at {args.scheduler}: {e}") from None
        except ValueError as e:
            # Not an address at all: a bad option value, which is usage (2) on every face.
            raise _Usage(f"--scheduler {args.scheduler}: {e}") from None
        try:
            client.wait_for_workers(1, timeout=args.worker_timeout)
        except Exception:
            client.close()
            raise _ClusterError(f"no worker joined the scheduler at {args.scheduler} within {args.worker_timeout:g} s") from None
        if not _gpu_workers(client):
            client.close()
            raise _ClusterError(f"no worker of the scheduler at {args.scheduler} declares a GPU: start workers with "
                                f"`dask worker {args.scheduler} --resources GPU=1`")
        return client, None
    cluster = distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       resources={"GPU": 1}, dashboard_address=None,
                                       silence_logs=logging.ERROR)
    return distributed.Client(cluster), cluster


def run(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    _require_dask()
    output = Path(args.output)
    aovs = args.aov.split(",") if args.aov else []
    # The library's own checks of an output, so that the farm refuses what `vkray render -o` refuses,
    # with the same message and exit code.
    vkray._vkray._check_output(output, aovs, args.exr_float, False)
    suffix = _PART_SUFFIX[output.suffix.lower()]
    settings = {"width": args.width, "height": args.height, "spp": args.spp, "seed": args.seed, "aovs": args.aov,
                "exr_float": args.exr_float}
    # Every scene read here first, so that a bad one fails before any worker starts.
    scenes = [str(Path(s).resolve()) for s in [args.scene, *args.frames]]
    rows = min(vkray.bands(scene, 1, width=args.width, height=args.height)[0][3] for scene in scenes)
    if args.regions is not None and args.regions > rows:
        raise _Usage(f"--regions {args.regions}: a frame renders {rows} rows, and a band has at least one row, "
                     f"so 1 to {rows}")

    targets = [_frame_output(output, frame, len(scenes)) for frame in range(len(scenes))]
    for target in targets:
        vkray._vkray._check_output(target, aovs, args.exr_float, False)

    client = cluster = folder = None
    try:
        # The parts go to disk as they arrive (the client holds none for long, however many frames),
        # in a folder beside the output, removed at the end whatever happens.
        try:
            folder = Path(tempfile.mkdtemp(prefix=f".{output.name}.parts-", dir=output.parent))
        except OSError as e:
            raise _CannotWrite(f"{output.parent}: cannot write there ({e.strerror})") from None
        client, cluster = _connect(args)
        started = time.perf_counter()
        gpus = _gpu_workers(client)
        regions = args.regions if args.regions is not None else min(rows, max(2, 2 * gpus))
        # Each frame's bands computed once, here, for all its parts.
        jobs = []  # (frame, band index, scene, region)
        for frame, scene in enumerate(scenes):
            for index, region in enumerate(vkray.bands(scene, regions, width=args.width, height=args.height)):
                jobs.append((frame, index, scene, region))
        _log(args.quiet, f"{len(jobs)} parts ({len(scenes)} frame{'s' if len(scenes) > 1 else ''} x {regions} bands) on "
                         f"{len(client.scheduler_info()['workers'])} workers with {gpus} GPU{'s' if gpus != 1 else ''}")
        _render_parts(client, args, jobs, settings, suffix, folder)
        rendered = time.perf_counter() - started
        # Every part is here: now, and only now, the outputs are written, each merged under a name
        # of its own in the parts' folder and then all renamed into place (one file system).
        merged = []
        for frame in range(len(scenes)):
            files = sorted(folder.glob(f"frame{frame:05d}-*{suffix}"))
            merged.append(folder / f"merged{frame:05d}{output.suffix}")
            summary = vkray.merge(merged[-1], files)
            if summary["mixed_devices"]:
                print("vkray.farm: warning: the parts were rendered on more than one device: the image agrees with a "
                      "single render within parity, not bit for bit", file=sys.stderr)
        with _no_interrupts():
            try:
                _commit(merged, targets, folder)
            except OSError as e:
                raise _CannotWrite(f"cannot put the output in place: {e}") from None
        for target in targets:
            _log(args.quiet, f"wrote {target}")
    finally:
        # A second Ctrl-C or a SIGTERM from a batch system must not leave the parts or the cluster.
        with _no_interrupts():
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
    _log(args.quiet, f"{len(jobs)} parts rendered in {rendered:.2f} s, merged in "
                     f"{time.perf_counter() - started - rendered:.2f} s")
    return 0


def _commit(merged: list[Path], targets: list[Path], folder: Path) -> None:
    """Renames each merged image to its target, all or none: a target that was there already is
    moved aside first and put back if a later rename fails."""
    done = []  # (target, what it was, in `folder`, or None)
    try:
        for frame, (file, target) in enumerate(zip(merged, targets)):
            previous = None
            if os.path.lexists(target):
                previous = folder / f"previous{frame:05d}"
                os.replace(target, previous)
            done.append((target, previous))
            os.replace(file, target)
    except BaseException:
        for target, previous in reversed(done):
            try:
                if previous is not None:
                    os.replace(previous, target)
                else:
                    target.unlink(missing_ok=True)
            except OSError:
                pass
        raise


def _render_parts(client: Any, args: argparse.Namespace, jobs: list, settings: dict[str, Any], suffix: str,
                  folder: Path) -> None:
    """Runs every job as a Dask task and writes each part to `folder` as it arrives; raises the first
    failure (vkray's exception, or the cluster's) after cancelling the rest."""
    import distributed

    run_id = uuid.uuid4().hex[:8]
    # The task by its module's name, so that Dask sends a reference the workers import, not this
    # module's code (when it runs as __main__, `python3 -m vkray.farm`).
    task = importlib.import_module("vkray.farm")._render_part
    futures = {}
    for frame, index, scene, region in jobs:
        future = client.submit(task, scene, region, settings, suffix, key=f"vkray-{run_id}-{frame}-{index}",
                               resources={"GPU": 1}, pure=False)
        futures[future] = (frame, index, region)
    done = 0
    part_seconds = trace_seconds = 0.0
    arrivals = distributed.as_completed(list(futures))
    # A task that needs a GPU waits for one however long it takes, so a job whose GPU workers are
    # all gone would wait for ever: between arrivals the loop looks every 2 s for GPUs left.
    without_gpus_since = None
    looked = time.monotonic()
    while futures:
        batch = arrivals.next_batch(block=False)
        if not batch:
            time.sleep(0.05)
            if time.monotonic() - looked < 2:
                continue
            looked = time.monotonic()
            if _gpu_workers(client):
                without_gpus_since = None
            elif without_gpus_since is None:
                without_gpus_since = looked
                _log(args.quiet, f"no worker with a GPU is left; waiting up to {args.worker_timeout:g} s for one")
            elif looked - without_gpus_since > args.worker_timeout:
                raise _ClusterError(f"no worker with a GPU has been in the cluster for {args.worker_timeout:g} s; "
                                    f"{len(futures)} of {len(jobs)} parts were not rendered")
            continue
        for future in sorted(batch, key=lambda f: futures[f][:2]):
            if future.status == "error":
                error = future.exception()
                client.cancel([other for other in futures if other is not future])
                raise error
            if future.status == "cancelled":
                raise _ClusterError(f"the cluster cancelled part {futures[future][1]} of frame {futures[future][0]} "
                                    f"(was the scheduler restarted?); {len(futures)} of {len(jobs)} parts were not "
                                    f"rendered")
            if future.status != "finished":
                # Its result was lost with its worker before it came here: Dask renders it again.
                arrivals.add(future)
                continue
            frame, index, region = futures.pop(future)
            part = future.result()
            future.release()
            file = folder / f"frame{frame:05d}-part{index:05d}{suffix}"
            try:
                file.write_bytes(part["data"])
                if part["record"] is not None:
                    file.with_name(file.name + ".json").write_bytes(part["record"])
            except OSError as e:
                raise _CannotWrite(f"{file}: cannot write a part there ({e.strerror})") from None
            done += 1
            part_seconds += part["seconds"]
            trace_seconds += part["stats"].get("trace_seconds", 0)
            _log(args.quiet, f"{done}/{len(jobs)} parts: frame {frame} rows {region[1]}-{region[3] - 1} in "
                             f"{part['seconds']:.2f} s ({part['stats'].get('trace_seconds', 0):.2f} s tracing) by "
                             f"{part['worker']} on {part['device']}")
    _log(args.quiet, f"the parts took {part_seconds:.2f} s on the workers, {trace_seconds:.2f} s of it tracing")


# The exit code of each kind of error, in the command line's classes: 1 bad input (an output that
# cannot be written, a machine without Dask or without the host memory for the job), 2 usage, 3
# device or cluster, 70 a bug of vkray's. Anything else is the cluster's (a worker lost too often,
# KilledWorker): 3.
_EXIT_CODES = ((_Usage, 2), (_CannotWrite, 1), (_MissingDask, 1), (MemoryError, 1), (_ClusterError, 3),
               (vkray.SceneError, 1), (vkray.UsageError, 2), (vkray.DeviceError, 3), (vkray.InternalError, 70))


# While set, Ctrl-C and SIGTERM are ignored: the outputs are being renamed into place (milliseconds),
# or the parts and the cluster cleaned up.
_shielded = False


def _interrupt(signum: int, frame: Any) -> None:
    if not _shielded:
        raise KeyboardInterrupt


@contextlib.contextmanager
def _no_interrupts():
    global _shielded
    previous, _shielded = _shielded, True
    try:
        yield
    finally:
        _shielded = previous


def main(argv: Optional[Sequence[str]] = None) -> int:
    # SIGTERM (a batch system's cancel, `kill`) stops the farm as Ctrl-C does: the cluster it
    # started is closed and nothing is written.
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _interrupt)
        signal.signal(signal.SIGTERM, _interrupt)
    try:
        return run(argv)
    except KeyboardInterrupt:
        print("vkray.farm: interrupted; nothing written", file=sys.stderr)
        return 130
    except Exception as e:
        code = next((code for kind, code in _EXIT_CODES if isinstance(e, kind)), None)
        own = code is not None and not isinstance(e, MemoryError)
        print(f"vkray.farm: error: {e if own else f'{type(e).__name__}: {e}'}", file=sys.stderr)
        return 3 if code is None else code


if __name__ == "__main__":
    sys.exit(main())
