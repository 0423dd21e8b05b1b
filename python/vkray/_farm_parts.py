"""The parts of a job, on the client's side: each band of each frame submitted as a Dask task, each
part written to the parts' folder as its first result arrives, and the watch for slow workers,
whose parts are rendered again on the others (speculative re-execution)."""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
import uuid
from pathlib import Path
from typing import Any, Callable, Optional

import vkray

from ._farm_cluster import _gpu_addresses
from ._farm_errors import _CannotWrite, _ClusterError
from ._farm_worker import _render_part, _worker_name

# A part's file type for each output type: float parts for every output, so that the merged image is
# the single render's exactly.
_PART_SUFFIX = {".exr": ".exr", ".pfm": ".pfm", ".png": ".pfm"}

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
    costs the job that limit, not Dask's worker-ttl (5 minutes). Whatever the job has to tell goes to
    `say`, a line at a time."""

    def __init__(self, client: Any, settings: dict[str, Any], suffix: str, folder: Path, *, slow_factor: float,
                 slow_floor: float, worker_timeout: float, say: Callable[[str], None]):
        import distributed

        self.client, self.settings, self.suffix, self.folder, self.say = client, settings, suffix, folder, say
        self.slow_factor, self.slow_floor, self.worker_timeout = slow_factor, slow_floor, worker_timeout
        run_id = uuid.uuid4().hex[:8]
        self.prefix, self.topic = f"vkray-{run_id}", f"vkray-farm-{run_id}"
        self.parts: list[_Part] = []
        self.part_of: dict[str, _Part] = {}  # attempt key -> its part
        self.only_on: dict[str, list[str]] = {}  # a later attempt's key -> the workers it may run on
        self.arrivals = distributed.as_completed()
        self.progress = _Progress(slow_factor, slow_floor)
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
        future = self.client.submit(_render_part, part.scene, part.region, self.settings, self.suffix, self.topic,
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
        self.say(f"the parts took {self.part_seconds:.2f} s on the workers, {self.trace_seconds:.2f} s of it tracing")

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
        self.say(f"{self.done}/{len(self.parts)} parts: frame {part.frame} rows {part.region[1]}-{part.region[3] - 1} "
                 f"in {result['seconds']:.2f} s ({tracing:.2f} s tracing) by {result['worker']} on "
                 f"{result['device']}{first}")

    def _write(self, part: _Part, result: dict[str, Any]) -> None:
        file = self.folder / f"frame{part.frame:05d}-part{part.index:05d}{self.suffix}"  # as _frame_parts finds it
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
            self.say(f"{part}: an attempt failed ({type(error).__name__}: {error}); another is under way")
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
            self.say(f"no worker with a GPU is left; waiting up to {self.worker_timeout:g} s for one")
        elif now - self.without_gpus_since > self.worker_timeout:
            raise _ClusterError(f"no worker with a GPU has been in the cluster for {self.worker_timeout:g} s; "
                                f"{len(self.parts) - self.done} of {len(self.parts)} parts were not rendered")

    def _heard_from(self, address: str) -> None:
        name = self.slow.pop(address, None)
        if name is not None:
            self.say(f"{name} is rendering again")

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
            self.say(f"slow: {self.slow[address]} has started or finished no part for {quiet:.1f} s, past "
                     f"{limit[0]:.1f} s ({self.slow_factor:g} x {limit[1]:.2f} s, the median time of the finished "
                     f"parts, and at least {self.slow_floor:g} s)"
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
                    self.say(f"slow: {why}: no other worker with a GPU can take it; waiting")
                continue
            self.say(f"slow: {why}: rendering it again on {', '.join(_name(a, workers) for a in others)}")
            self.stuck.discard(part)
            self.submit(part, others)


def _frame_parts(folder: Path, frame: int, suffix: str) -> list[Path]:
    """The part files of `frame` that a job wrote to `folder`, in the order of their bands."""
    return sorted(folder.glob(f"frame{frame:05d}-part*{suffix}"))


def _name(address: str, workers: dict[str, Any]) -> str:
    return _worker_name(workers[address]["name"]) if address in workers else address
