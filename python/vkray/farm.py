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
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib
import importlib.util
import logging
import math
import os
import shutil
import signal
import statistics
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
                 suffix: str, topic: str) -> dict[str, Any]:
    """A Dask task: renders `region` of `scene` and returns the part file's bytes (and a PFM part's
    record) with what it cost. It tells the job on `topic` when it starts rendering, so that the job
    sees a worker that stops making progress."""
    global _renderer
    import distributed

    worker = distributed.get_worker()
    with _renderer_lock, tempfile.TemporaryDirectory(prefix="vkray-part-") as folder:
        start = time.perf_counter()
        worker.log_event(topic, {"key": worker.get_current_task(), "address": worker.address})
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
            "worker": _worker_name(worker.name),
            "address": worker.address,
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
    p.add_argument("--slow-factor", type=_number("number", 1, 1e6), default=4.0, metavar="F",
                   help="a worker that holds parts but has started or finished none for F times the median time of "
                        "the finished parts (and --slow-floor seconds) is slow: its parts are rendered again on other "
                        "workers, and the first result of each is used (default 4)")
    p.add_argument("--slow-floor", type=_seconds, default=10.0, metavar="SECONDS",
                   help="the least time that makes a worker slow, whatever the median (default 10)")
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


def _gpu_addresses(workers: dict[str, Any]) -> list[str]:
    """The workers (scheduler_info()["workers"]) that declare a GPU."""
    return [address for address, w in workers.items() if w.get("resources", {}).get("GPU", 0) >= 1]


def _gpu_workers(client: Any) -> int:
    return len(_gpu_addresses(client.scheduler_info()["workers"]))


def _connect(args: argparse.Namespace, workspace: Optional[Path]):  # -> (Client, cluster or None)
    """A client of the scheduler at --scheduler, or of a LocalCluster started here whose workers keep
    their files in `workspace`."""
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
                                       silence_logs=logging.ERROR, local_directory=str(workspace))
    try:
        return distributed.Client(cluster), cluster
    except BaseException:
        _close(None, cluster)
        raise


def run(argv: Optional[Sequence[str]] = None) -> int:
    args = _parser().parse_args(argv)
    _require_dask()
    output = Path(args.output)
    aovs = args.aov.split(",") if args.aov else []
    # The library's own checks of an output, so that the farm refuses what `vkray render -o` refuses,
    # with the same message and exit code.
    vkray._vkray._check_output(output, aovs, args.exr_float, False)
    # The numbers against the library's table of limits, which `vkray render` checks its flags with:
    # the same range and words, "--width: expected an integer from 1 to 16384, got 20000".
    try:
        vkray._request(args.width, args.height, args.spp, args.seed, (), None)
    except vkray.UsageError as e:
        raise _Usage(f"--{e}") from None
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
        client, cluster = _connect(args, workspace)
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
        job = _Job(client, args, settings, suffix, folder)
        for frame, index, scene, region in jobs:
            job.submit(_Part(frame, index, scene, region))
        job.wait()
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
        merged_in = time.perf_counter() - started - rendered
    finally:
        # A second Ctrl-C or a SIGTERM from a batch system must not leave the parts or the cluster.
        with _no_interrupts():
            _close(client, cluster)
            for remove in (folder, workspace):
                if remove is not None:
                    shutil.rmtree(remove, ignore_errors=True)
    _log(args.quiet, f"{len(jobs)} parts rendered in {rendered:.2f} s, merged in {merged_in:.2f} s")
    return 0


# How long closing the client, and then the LocalCluster, may take.
_CLOSE_SECONDS = 20


def _close(client: Any, cluster: Any) -> None:
    """Closes the client and a LocalCluster in bounded time, and then ends any of the cluster's worker
    processes still there (one stopped, or stuck in a driver, does not answer): nothing the job
    started is left running."""
    pids = [nanny.pid for nanny in cluster.workers.values() if getattr(nanny, "pid", None)] if cluster else []
    for closing in (client, cluster):
        if closing is not None:
            with contextlib.suppress(Exception):
                closing.close(timeout=_CLOSE_SECONDS)
    import psutil  # a dependency of Dask's distributed

    for pid in pids:
        with contextlib.suppress(psutil.Error):
            process = psutil.Process(pid)
            if process.ppid() == os.getpid():
                process.kill()


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


# ---- the job: each part's attempts, and the watch for slow workers --------------------------------

# How often the job looks at the cluster: the workers with a GPU, what each holds, what each started.
_LOOK_SECONDS = 1.0


@dataclasses.dataclass(eq=False)
class _Part:
    """A band of a frame and the Dask tasks that render it: the first, and one more each time the
    workers that held the earlier ones were slow."""
    frame: int
    index: int
    scene: str
    region: tuple[int, int, int, int]
    attempts: list = dataclasses.field(default_factory=list)  # futures, in the order submitted
    done: bool = False  # its part file is written; a later result of it is not used

    def __str__(self) -> str:
        return f"part {self.index} of frame {self.frame} (rows {self.region[1]}-{self.region[3] - 1})"


class _Progress:
    """What the workers were seen doing: when each last started or finished a part, when each attempt
    started and where, and how long the finished parts took. From that, how long a worker may go
    without starting or finishing a part before it counts as slow."""

    def __init__(self, factor: float, floor: float):
        self.factor, self.floor = factor, floor
        # (when it came, the event) for each start event, appended by the client's thread as it comes.
        self.events: list[tuple[float, dict[str, str]]] = []
        self.events_read = 0
        self.since: dict[str, float] = {}  # worker address -> when it last started or finished a part, or got one
        self.started: dict[str, tuple[str, float]] = {}  # attempt key -> (worker address, when it started)
        self.seconds: dict[int, list[float]] = {}  # frame -> how long each of its finished parts took
        self.busy: set[str] = set()  # the workers that held parts at the last look

    def heard(self, event: tuple[float, dict[str, str]]) -> None:
        """The handler of the job's topic: a worker started an attempt (Dask's event, (time, message))."""
        self.events.append((time.monotonic(), event[1]))

    def read(self) -> list[str]:
        """Takes the start events not read yet; returns the workers they came from."""
        new = self.events[self.events_read:]
        self.events_read += len(new)
        for when, event in new:
            self.started[event["key"]] = (event["address"], when)
            self.since[event["address"]] = max(self.since.get(event["address"], when), when)
        return [event["address"] for _, event in new]

    def finished(self, address: str, frame: int, seconds: float, now: float) -> None:
        self.since[address] = now
        self.seconds.setdefault(frame, []).append(seconds)

    def hold(self, held: dict[str, list[str]], now: float) -> None:
        """Notes which workers hold parts now: one that held none at the last look starts its clock."""
        busy = {address for address, keys in held.items() if keys}
        for address in busy - self.busy:
            self.since[address] = now
        self.busy = busy

    def expected(self, frame: int) -> Optional[float]:
        """A part's expected seconds: the median of its frame's finished parts (the bands of a frame are
        of about equal work), else of all finished parts; None before any part is in."""
        seconds = self.seconds.get(frame) or [s for each in self.seconds.values() for s in each]
        return statistics.median(seconds) if seconds else None

    def limit(self, frames: set[int]) -> Optional[tuple[float, float]]:
        """(how long, the expected part's seconds): a worker holding parts of `frames` is slow once it has
        started or finished none for --slow-factor times the longest of their expected times, and at
        least --slow-floor seconds."""
        expected = [e for e in map(self.expected, frames) if e is not None]
        return (max(self.floor, self.factor * max(expected)), max(expected)) if expected else None


class _Job:
    """Every part of every frame as Dask tasks; each part is written to `folder` when its first result
    arrives. A worker that holds parts but has started or finished none for far longer than a part
    takes (`_Progress.limit`) is slow: each part it holds is submitted again to the other workers with
    a GPU, the first result of a part is used and its other attempts are cancelled (speculative
    execution, as MapReduce's backup tasks and Spark's speculation), so that a stopped or stuck worker
    costs the job that limit, not Dask's worker-ttl (5 minutes)."""

    def __init__(self, client: Any, args: argparse.Namespace, settings: dict[str, Any], suffix: str, folder: Path):
        import distributed

        self.client, self.args, self.settings, self.suffix, self.folder = client, args, settings, suffix, folder
        run_id = uuid.uuid4().hex[:8]
        self.prefix, self.topic = f"vkray-{run_id}", f"vkray-farm-{run_id}"
        # The task by its module's name, so that Dask sends a reference the workers import, not this
        # module's code (when it runs as __main__, `python3 -m vkray.farm`).
        self.task = importlib.import_module("vkray.farm")._render_part
        self.parts: list[_Part] = []
        self.part_of: dict[str, _Part] = {}  # attempt key -> its part
        self.only_on: dict[str, list[str]] = {}  # a later attempt's key -> the workers it may run on
        self.arrivals = distributed.as_completed()
        self.progress = _Progress(args.slow_factor, args.slow_floor)
        # Each start event comes to this client once, as it happens (before any task is submitted).
        client.subscribe_topic(self.topic, self.progress.heard)
        self.slow: dict[str, str] = {}  # a slow worker's address -> its name
        self.stuck: set[_Part] = set()  # parts said to have no other worker to go to
        self.without_gpus_since: Optional[float] = None
        self.done = 0  # parts written
        self.part_seconds = self.trace_seconds = 0.0

    def submit(self, part: _Part, workers: Optional[list[str]] = None) -> None:
        if not part.attempts:
            self.parts.append(part)
        key = f"{self.prefix}-{part.frame}-{part.index}-{len(part.attempts)}"
        # A later attempt goes to `workers` only, ahead of the parts not started yet: the job waits for it.
        future = self.client.submit(self.task, part.scene, part.region, self.settings, self.suffix, self.topic,
                                    key=key, resources={"GPU": 1}, pure=False, workers=workers,
                                    priority=1 if workers else 0)
        part.attempts.append(future)
        self.part_of[key] = part
        if workers:
            self.only_on[key] = workers
        self.arrivals.add(future)

    def wait(self) -> None:
        """Writes each part as it arrives, until all are in; raises the first failure (vkray's, or the
        cluster's) after cancelling the rest."""
        looked = time.monotonic()
        while self.done < len(self.parts):
            batch = self.arrivals.next_batch(block=False)
            for future in sorted(batch, key=lambda f: (self.part_of[f.key].frame, self.part_of[f.key].index)):
                self._arrive(future)
            if batch:
                continue
            time.sleep(0.05)
            if time.monotonic() - looked >= _LOOK_SECONDS:
                looked = time.monotonic()
                self._look(looked)
        _log(self.args.quiet, f"the parts took {self.part_seconds:.2f} s on the workers, {self.trace_seconds:.2f} s of "
                              f"it tracing")

    # ---- a result, or a failure, arrives

    def _arrive(self, future: Any) -> None:
        part = self.part_of[future.key]
        if part.done:
            # Another attempt of this part came first: this one's result is not used.
            future.release()
            return
        if future.status in ("error", "cancelled"):
            self._failed(part, future)
            return
        if future.status != "finished":
            # Its result was lost with its worker before it came here: Dask renders it again.
            self.arrivals.add(future)
            return
        result = future.result()
        part.done = True
        self.done += 1
        others = [f for f in part.attempts if f is not future]
        if others:
            self.client.cancel(others)
        future.release()
        self._write(part, result)
        self.progress.finished(result["address"], part.frame, result["seconds"], time.monotonic())
        self._heard_from(result["address"])
        self.part_seconds += result["seconds"]
        tracing = result["stats"].get("trace_seconds", 0)
        self.trace_seconds += tracing
        first = f" (the first of {len(part.attempts)} attempts; the others are cancelled)" if others else ""
        _log(self.args.quiet, f"{self.done}/{len(self.parts)} parts: frame {part.frame} rows {part.region[1]}-"
                              f"{part.region[3] - 1} in {result['seconds']:.2f} s ({tracing:.2f} s tracing) by "
                              f"{result['worker']} on {result['device']}{first}")

    def _write(self, part: _Part, result: dict[str, Any]) -> None:
        file = self.folder / f"frame{part.frame:05d}-part{part.index:05d}{self.suffix}"
        try:
            file.write_bytes(result["data"])
            if result["record"] is not None:
                file.with_name(file.name + ".json").write_bytes(result["record"])
        except OSError as e:
            raise _CannotWrite(f"{file}: cannot write a part there ({e.strerror})") from None

    def _failed(self, part: _Part, future: Any) -> None:
        """A part's failure fails the job, unless it is the cluster's (not vkray's) and another attempt
        of the part is still under way."""
        error = future.exception() if future.status == "error" else _ClusterError(
            f"the cluster cancelled {part} (was the scheduler restarted?); "
            f"{len(self.parts) - self.done} of {len(self.parts)} parts were not rendered")
        if not isinstance(error, vkray.Error) and any(not f.done() for f in part.attempts):
            _log(self.args.quiet, f"{part}: an attempt failed ({type(error).__name__}: {error}); another is under way")
            return
        self.client.cancel([f for p in self.parts for f in p.attempts if f is not future and not f.done()])
        raise error

    # ---- the periodic look at the cluster

    def _look(self, now: float) -> None:
        workers = self.client.scheduler_info()["workers"]
        gpus = set(_gpu_addresses(workers))
        self._check_gpus(gpus, now)
        for address in self.progress.read():
            self._heard_from(address)
        held = {address: [key for key in keys if key in self.part_of and not self.part_of[key].done]
                for address, keys in self.client.processing().items()}
        self.progress.hold(held, now)
        self._find_slow(held, workers, now)
        self._speculate(held, gpus, workers, now)

    def _check_gpus(self, gpus: set[str], now: float) -> None:
        """A task that needs a GPU waits for one however long it takes, so a job whose GPU workers are
        all gone would wait for ever: it fails after --worker-timeout seconds without any."""
        if gpus:
            self.without_gpus_since = None
        elif self.without_gpus_since is None:
            self.without_gpus_since = now
            _log(self.args.quiet, f"no worker with a GPU is left; waiting up to {self.args.worker_timeout:g} s for one")
        elif now - self.without_gpus_since > self.args.worker_timeout:
            raise _ClusterError(f"no worker with a GPU has been in the cluster for {self.args.worker_timeout:g} s; "
                                f"{len(self.parts) - self.done} of {len(self.parts)} parts were not rendered")

    def _heard_from(self, address: str) -> None:
        name = self.slow.pop(address, None)
        if name is not None:
            _log(self.args.quiet, f"{name} is rendering again")

    def _find_slow(self, held: dict[str, list[str]], workers: dict[str, Any], now: float) -> None:
        heartbeats = [w["last_seen"] for w in workers.values() if "last_seen" in w]
        for address, keys in held.items():
            if not keys or address in self.slow:
                continue
            limit = self.progress.limit({self.part_of[key].frame for key in keys})
            quiet = now - self.progress.since.get(address, now)
            if limit is None or quiet <= limit[0]:
                continue
            silent = max(heartbeats, default=0) - workers.get(address, {}).get("last_seen", math.inf)
            self.slow[address] = _name(address, workers)
            _log(self.args.quiet, f"slow: {self.slow[address]} has started or finished no part for {quiet:.1f} s, past "
                                  f"{limit[0]:.1f} s ({self.args.slow_factor:g} x {limit[1]:.2f} s, the median time of "
                                  f"the finished parts, and at least {self.args.slow_floor:g} s)"
                                  + (f"; its last heartbeat was {silent:.0f} s ago" if silent >= 5 else ""))

    def _alive(self, future: Any, holder: dict[str, str], gpus: set[str]) -> bool:
        """Whether an attempt may still bring its part: finished, or held by a worker that is not
        slow, or waiting for a worker that is still in the cluster."""
        if future.status == "finished":
            return True
        if future.done():
            return False
        if future.key in holder:
            return holder[future.key] not in self.slow
        return future.key not in self.only_on or bool(gpus.intersection(self.only_on[future.key]))

    def _speculate(self, held: dict[str, list[str]], gpus: set[str], workers: dict[str, Any], now: float) -> None:
        """Submits again each part none of whose attempts may still bring it, to the GPU workers that
        are not slow, and says why."""
        holder = {key: address for address, keys in held.items() for key in keys}
        others = sorted(gpus - self.slow.keys())
        for part in self.parts:
            if part.done or any(self._alive(f, holder, gpus) for f in part.attempts):
                continue
            key = next((f.key for f in reversed(part.attempts) if f.key in holder), None)
            address = holder.get(key)
            started = self.progress.started.get(key)
            if address in self.slow:
                why = (f"{part}, running on {self.slow[address]} for {now - started[1]:.1f} s"
                       if started and started[0] == address else f"{part}, waiting on {self.slow[address]}")
            else:
                why = f"{part}, whose last attempt was for workers that have left"
            if not others:
                if part not in self.stuck:
                    self.stuck.add(part)
                    _log(self.args.quiet, f"slow: {why}: no other worker with a GPU can take it; waiting")
                continue
            _log(self.args.quiet, f"slow: {why}: rendering it again on {', '.join(_name(a, workers) for a in others)}")
            self.stuck.discard(part)
            self.submit(part, others)


def _name(address: str, workers: dict[str, Any]) -> str:
    return _worker_name(workers[address]["name"]) if address in workers else address


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
