"""python3 -m vkray.farm against a real Dask cluster on this machine: a scheduler and two workers,
each a process of its own on 127.0.0.1 (started and stopped here), that declare a GPU as Dask
resource, as workers on GPU machines would. The farm's output is compared byte for byte with a single
`vkray render`; a worker is killed in the middle of a job (and then the only one), and a worker whose
device fails fails the job cleanly."""

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
import types
from pathlib import Path
from typing import Optional

import distributed
import numpy as np
import OpenImageIO as oiio
import psutil
import pytest

import vkray
import vkray.farm as farm_module
from vkray._farm_outputs import _commit
from conftest import ROOT, SCENES, run

# Every test renders the Cornell box with paths: cheap, and noisy, so that any wrong sample shows.
RENDER = ["--width", "64", "--height", "48", "--spp", "8"]


class Cluster:
    """A scheduler and workers, each its own process, as `dask scheduler` and `dask worker` start them."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.file = folder / "scheduler.json"
        self.processes: list[subprocess.Popen] = []
        self.workers: list[subprocess.Popen] = []
        self.scheduler = self._start("scheduler", [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                                                   "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
                                                   str(self.file)])
        try:
            deadline = time.monotonic() + 60
            while not self.file.exists() or not self.file.read_text().strip().endswith("}"):
                assert self.scheduler.poll() is None, self.log("scheduler")
                assert time.monotonic() < deadline, "the scheduler did not start within 60 s"
                time.sleep(0.1)
            self.address = json.loads(self.file.read_text())["address"]
        except BaseException:
            self.close()
            raise

    def _start(self, name: str, command: list[str], env: dict = None) -> subprocess.Popen:
        with open(self.folder / f"{name}.log", "w") as log:
            process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=env, start_new_session=True)
        self.processes.append(process)
        return process

    def log(self, name: str) -> str:
        return (self.folder / f"{name}.log").read_text()

    def add_worker(self, name: str, gpu: bool = True, **env: str) -> subprocess.Popen:
        # --no-nanny: the worker is the process; killing it loses the worker, as a crashed machine would.
        worker = self._start(name, [sys.executable, "-m", "distributed.cli.dask_worker", self.address, "--nthreads",
                                    "1", "--no-nanny", "--no-dashboard", *(["--resources", "GPU=1"] if gpu else []),
                                    "--name", name], env={**os.environ, **env})
        self.workers.append(worker)
        return worker

    def wait_for_workers(self, count: int) -> None:
        with distributed.Client(self.address, timeout="30s") as client:
            client.wait_for_workers(count, timeout=60)

    def close(self) -> None:
        for process in reversed(self.processes):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in self.processes:
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    yield c
    c.close()


def farm(*args: str, **kwargs) -> subprocess.Popen:
    # A session of its own, so that a farm that overstays is killed with its LocalCluster's workers.
    return subprocess.Popen([sys.executable, "-m", "vkray.farm", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True, **kwargs)


def finish(job: subprocess.Popen, timeout: float) -> str:
    """The farm's stderr once it ends; killed (with its processes) if it runs past `timeout` s."""
    try:
        return job.communicate(timeout=timeout)[1]
    except subprocess.TimeoutExpired:
        os.killpg(job.pid, signal.SIGKILL)
        job.communicate()
        raise


def single_render(vkray_command, scene, out: Path, *extra: str) -> bytes:
    run(vkray_command, "render", str(scene), *RENDER, *extra, "-o", str(out), "-q")
    return out.read_bytes()


def test_four_regions_on_two_workers_merge_into_the_bytes_of_one_render(cluster, scenes, vkray_command, tmp_path):
    cluster.add_worker("worker-a")
    cluster.add_worker("worker-b")
    cluster.wait_for_workers(2)
    scene = scenes / "cornell-path.json"
    out = tmp_path / "farm.exr"
    job = farm(str(scene), *RENDER, "--aov", "albedo,depth", "-o", str(out), "--regions", "4", "--scheduler",
               cluster.address)
    err = finish(job, 300)
    assert job.returncode == 0, err
    assert "4/4 parts" in err and f"wrote {out}" in err, err
    assert out.read_bytes() == single_render(vkray_command, scene, tmp_path / "single.exr", "--aov", "albedo,depth")
    # Both workers took parts, and no part file was left beside the output.
    assert "by worker-a on" in err and "by worker-b on" in err, err
    assert list(tmp_path.glob(".farm*")) == []


HEAVY = ["--width", "64", "--height", "48", "--spp", "96"]


def kill_once_busy(cluster: Cluster, name: str, victim: subprocess.Popen, job: subprocess.Popen) -> None:
    """Kills the worker `name` once it is rendering a part of `job`."""
    with distributed.Client(cluster.address, timeout="30s") as client:
        deadline = time.monotonic() + 120
        while True:
            workers = client.scheduler_info()["workers"]
            busy = {workers[w]["name"]: keys for w, keys in client.processing().items() if w in workers}
            if busy.get(name):
                break
            assert job.poll() is None, job.communicate()[1]
            assert time.monotonic() < deadline, f"{name} never got a part"
            time.sleep(0.05)
    victim.send_signal(signal.SIGKILL)


def test_a_worker_killed_mid_job_has_its_part_rendered_elsewhere(cluster, scenes, vkray_command, tmp_path):
    victim = cluster.add_worker("victim")
    cluster.add_worker("survivor")
    cluster.wait_for_workers(2)
    scene = scenes / "cornell-path.json"
    out = tmp_path / "farm.pfm"
    job = farm(str(scene), *HEAVY, "-o", str(out), "--regions", "6", "--scheduler", cluster.address)
    kill_once_busy(cluster, "victim", victim, job)
    err = finish(job, 300)
    assert job.returncode == 0, err
    assert "6/6 parts" in err and "by survivor on" in err, err
    single = tmp_path / "single.pfm"
    run(vkray_command, "render", str(scene), *HEAVY, "-o", str(single), "-q")
    assert out.read_bytes() == single.read_bytes()


def test_a_job_whose_last_gpu_worker_is_lost_fails_instead_of_waiting(cluster, scenes, tmp_path):
    # Dask keeps a task that needs a GPU waiting for one for ever; the farm gives up after
    # --worker-timeout seconds without any.
    victim = cluster.add_worker("only")
    cluster.wait_for_workers(1)
    out = tmp_path / "farm.pfm"
    job = farm(str(scenes / "cornell-path.json"), *HEAVY, "-o", str(out), "--regions", "4", "--worker-timeout", "3",
               "--scheduler", cluster.address)
    kill_once_busy(cluster, "only", victim, job)
    err = finish(job, 120)
    assert job.returncode == 3, err
    assert "no worker with a GPU has been in the cluster for 3 s" in err, err
    assert list(tmp_path.glob("farm*")) == [] and list(tmp_path.glob(".farm*")) == []


def test_a_cluster_without_gpu_workers_is_refused(cluster, scenes, tmp_path):
    cluster.add_worker("cpu-only", gpu=False)
    cluster.wait_for_workers(1)
    job = farm(str(scenes / "cornell.json"), *RENDER, "-o", str(tmp_path / "farm.pfm"), "--scheduler", cluster.address)
    err = finish(job, 120)
    assert job.returncode == 3, err
    assert "declares a GPU" in err and "--resources GPU=1" in err, err
    assert list(tmp_path.glob("farm*")) == []


def test_a_part_that_fails_fails_the_job_with_vkrays_message_and_writes_nothing(cluster, scenes, tmp_path):
    # One worker's device does not exist: every part it takes fails as `vkray render --device` would,
    # and the job fails although the other worker renders its parts.
    cluster.add_worker("broken", VKRAY_DEVICE="no-such-gpu")
    cluster.add_worker("fine")
    cluster.wait_for_workers(2)
    out = tmp_path / "farm.exr"
    job = farm(str(scenes / "cornell-path.json"), *HEAVY, "-o", str(out), "--regions", "6", "--scheduler",
               cluster.address)
    err = finish(job, 300)
    assert job.returncode == 3, err
    assert "vkray.farm: error:" in err and "no-such-gpu" in err, err
    assert list(tmp_path.glob("farm*")) == [] and list(tmp_path.glob(".farm*")) == []


class Stderr:
    """A running farm's stderr, line by line as it comes (read by a thread of its own)."""

    def __init__(self, job: subprocess.Popen):
        self.job, self.lines, self.changed = job, [], threading.Condition()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        for line in self.job.stderr:
            with self.changed:
                self.lines.append(line)
                self.changed.notify_all()

    def wait_for(self, pattern: str, timeout: float) -> re.Match:
        with self.changed:
            assert self.changed.wait_for(lambda: self._match(pattern) or self.job.poll() is not None, timeout), \
                f"no line matched {pattern!r} within {timeout} s:\n{self.text()}"
            match = self._match(pattern)
            assert match, f"the farm ended (exit {self.job.returncode}) before a line matched {pattern!r}:\n{self.text()}"
            return match

    def _match(self, pattern: str) -> Optional[re.Match]:
        return next((m for m in map(re.compile(pattern).search, self.lines) if m), None)

    def text(self) -> str:
        return "".join(self.lines)


def processes_in_session(sid: int) -> list[psutil.Process]:
    """The processes still running (zombies aside) in the session of the farm's process `sid`."""
    left = []
    for process in psutil.process_iter():
        with contextlib.suppress(psutil.Error, OSError):
            if os.getsid(process.pid) == sid and process.status() != psutil.STATUS_ZOMBIE:
                left.append(process)
    return left


# A render whose parts take a second or so each on lavapipe, so that a worker is stopped while it
# holds parts, long before the others are done.
SLOW = ["--width", "128", "--height", "96", "--spp", "1024"]


@pytest.fixture(scope="module")
def slow_single_render(tmp_path_factory) -> bytes:
    """`vkray render` of SLOW, once for the tests that compare with it."""
    out = tmp_path_factory.mktemp("single") / "single.pfm"
    run(os.environ["VKRAY_EXECUTABLE"], "render", str(SCENES / "cornell-path.json"), *SLOW, "-o", str(out), "-q")
    return out.read_bytes()


@pytest.mark.parametrize("resumed", [False, True], ids=["stays-stopped", "resumed-later"])
def test_a_stopped_worker_has_its_parts_rendered_elsewhere_and_is_ended(scenes, tmp_path, slow_single_render, resumed):
    # A worker process of the farm's LocalCluster is stopped (SIGSTOP) while it holds parts: Dask
    # would keep them for its worker-ttl of five minutes. The farm says which parts wait on that
    # worker and renders them on the other one; a worker that continues later (SIGCONT) must not
    # break the job either.
    out = tmp_path / "farm.pfm"
    job = farm(str(scenes / "cornell-path.json"), *SLOW, "-o", str(out), "--workers", "2", "--regions", "8")
    err = Stderr(job)
    victim = None
    try:
        address = err.wait_for(r"scheduler (tcp://\S+)", 120)[1]
        with distributed.Client(address, timeout="30s") as client:
            pids = client.run(os.getpid)
            deadline = time.monotonic() + 60
            while not any(client.processing().values()):
                assert time.monotonic() < deadline and job.poll() is None, err.text()
                time.sleep(0.05)
            holder = max(client.processing().items(), key=lambda item: len(item[1]))[0]
            victim = pids[holder]
            os.kill(victim, signal.SIGSTOP)
            assert client.processing()[holder], "the stopped worker held no part"
            name = f"worker {client.scheduler_info()['workers'][holder]['name']}"
        # Which parts wait on which worker, and where they go.
        slow = err.wait_for(rf"slow: part \d+ of frame 0 \(rows \d+-\d+\), (running|waiting) on {name}( for [\d.]+ s)?: "
                            rf"rendering it again on (worker \d)$", 240)
        if resumed:
            os.kill(victim, signal.SIGCONT)
        # Well within Dask's five minutes, whatever the load on this machine.
        job.wait(timeout=240)
        err.reader.join(timeout=30)
        assert job.returncode == 0, err.text()
        assert f"slow: {name} has started or finished no part for" in err.text(), err.text()
        assert slow[3] != name, err.text()
        # Each part was written once, and the merged image is a single render's.
        assert len(re.findall(r"^vkray\.farm: \d+/8 parts:", err.text(), re.MULTILINE)) == 8, err.text()
        assert "8/8 parts" in err.text() and f"wrote {out}" in err.text(), err.text()
        if not resumed:
            assert re.search(rf"by {slow[3]} on .*\(the first of 2 attempts; the others are cancelled\)", err.text()), \
                err.text()
        assert out.read_bytes() == slow_single_render
        assert list(tmp_path.glob(".farm*")) == []
        # Nothing the job started is left, the stopped worker included.
        deadline = time.monotonic() + 30
        while processes_in_session(job.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert processes_in_session(job.pid) == [], [p.cmdline() for p in processes_in_session(job.pid)]
    finally:
        if victim is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(victim, signal.SIGCONT)
                os.kill(victim, signal.SIGKILL)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(job.pid, signal.SIGKILL)
        job.wait()


def test_closing_a_cluster_that_does_not_answer_ends_its_worker_processes():
    # As a LocalCluster whose close times out on a stopped worker process: the farm ends the process.
    class Unanswering:
        def __init__(self, pid: int):
            self.workers = {0: types.SimpleNamespace(pid=pid)}

        def close(self, timeout: Optional[float] = None) -> None:
            raise TimeoutError(f"the cluster did not close within {timeout} s")

    worker = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        worker.send_signal(signal.SIGSTOP)
        farm_module._close(None, Unanswering(worker.pid))
        assert worker.wait(timeout=30) == -signal.SIGKILL
    finally:
        worker.kill()
        worker.wait()


def test_frames_on_a_local_cluster(scenes, vkray_command, tmp_path):
    out = tmp_path / "frame.pfm"
    job = farm(str(scenes / "cornell.json"), "--frames", str(scenes / "cornell-spheres.json"), *RENDER, "-o", str(out),
               "--regions", "2")
    err = finish(job, 300)
    assert job.returncode == 0, err
    for frame, scene in enumerate(["cornell.json", "cornell-spheres.json"]):
        single = tmp_path / f"single{frame}.pfm"
        run(vkray_command, "render", str(scenes / scene), *RENDER, "-o", str(single), "-q")
        assert (tmp_path / f"frame.{frame:04d}.pfm").read_bytes() == single.read_bytes(), scene


def test_sigterm_stops_the_job_and_writes_nothing(scenes, tmp_path):
    out = tmp_path / "farm.pfm"
    job = farm(str(scenes / "cornell-path.json"), "--width", "128", "--height", "96", "--spp", "256", "-o", str(out),
               "--regions", "8")
    # The parts' folder appears once the cluster is up.
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".farm.pfm.parts-*")):
        assert job.poll() is None, job.communicate()[1]
        assert time.monotonic() < deadline, "the farm did not start"
        time.sleep(0.05)
    job.send_signal(signal.SIGTERM)
    err = finish(job, 120)
    assert job.returncode == 130, err
    assert "interrupted; nothing written" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, code, says", [
    (["missing.json", "-o", "x.pfm"], 1, "missing.json"),
    # Output paths as `vkray render -o` refuses them: a path that cannot be written is bad input (1),
    # what cannot be asked of a file type is usage (2).
    (["{scenes}/cornell.json", "-o", "x.txt"], 1, "unknown image type"),
    (["{scenes}/cornell.json", "-o", "{scenes}/cornell.json/x.pfm"], 1, "cornell.json does not exist"),
    (["{scenes}/cornell.json", "-o", "{scenes}"], 1, "unknown image type"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--aov", "depth"], 2, "EXR files only"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--height", "8", "--regions", "9"], 2, "1 to 8"),
    (["{scenes}/cornell.json", "-o", "x.exr", "--aov", "depth,shadows"], 2, 'unknown pass "shadows"'),
    # Past the library's limits: the words `vkray render` uses for its flags (test_faces.py holds
    # more, each given to every face). Integers are read as it reads them: decimal digits, or '-'
    # and digits, which no option takes; the word after the option is its value, whatever it is.
    (["{scenes}/cornell.json", "-o", "x.pfm", "--seed", "-1"], 2, "--seed: expected an integer from 0 to 4294967295, got -1"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--seed", "-0"], 2, "--seed: expected an integer from 0 to 4294967295, got -0"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--width", "-05"], 2, "--width: expected an integer from 1 to 16384, got -05"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--width", "20000"], 2, "--width: expected an integer from 1 to 16384, got 20000"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--seed", "9" * 5000], 2,
     "--seed: expected an integer from 0 to 4294967295, got " + "9" * 60 + "..."),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--spp", "70000"], 2, "--spp: expected an integer from 1 to 65536, got 70000"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--spp", "many"], 2, '--spp: expected a decimal integer, got "many"'),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--width", "-x"], 2, '--width: expected a decimal integer, got "-x"'),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--height", "4\x1b[2J"], 2, '--height: expected a decimal integer, got "4?[2J"'),
    # The farm's own integers follow the same rules.
    (["{scenes}/cornell.json", "-o", "x.pfm", "--workers", "0"], 2, "--workers: expected an integer from 1 to 256, got 0"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--workers", "+2"], 2, '--workers: expected a decimal integer, got "+2"'),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--height", "8", "--regions", "0"], 2, "--regions 0: a frame renders 8 rows"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--regions", "\u0663"], 2, '--regions: expected a decimal integer, got "\u0663"'),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--scheduler", "tcp://127.0.0.1:1", "--worker-timeout", "2"], 3,
     "cannot reach the scheduler at tcp://127.0.0.1:1"),
    # Not an address at all: a bad option value, as `vkray render --width x` is.
    (["{scenes}/cornell.json", "-o", "x.pfm", "--scheduler", "no-port"], 2, "--scheduler no-port: missing port number"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--slow-factor", "1"], 2, "--slow-factor: 1 is not more than 1"),
    (["{scenes}/cornell.json", "-o", "x.pfm", "--slow-floor", "0"], 2, "--slow-floor: 0 is not more than 0"),
])
def test_bad_jobs_fail_before_any_work_with_a_message(scenes, tmp_path, args, code, says):
    job = farm(*[a.format(scenes=scenes) for a in args], cwd=tmp_path)
    err = finish(job, 120)
    assert job.returncode == code, err
    assert says in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("error, code", [
    (vkray.SceneError("scene.json: key"), 1), (farm_module._CannotWrite("out: disk full"), 1), (MemoryError(), 1),
    (farm_module._Usage("--regions"), 2), (vkray.UsageError("width"), 2), (vkray.DeviceError("lost"), 3),
    (farm_module._ClusterError("no worker"), 3), (distributed.comm.CommClosedError("lost"), 3),
    (vkray.InternalError("bug"), 70), (KeyboardInterrupt(), 130),
])
def test_each_kind_of_error_exits_with_the_command_lines_code(monkeypatch, capsys, error, code):
    def fail(argv):
        raise error
    monkeypatch.setattr(farm_module, "run", fail)
    monkeypatch.setattr(signal, "signal", lambda *args: None)  # pytest's own handlers stay
    assert farm_module.main([]) == code
    assert capsys.readouterr().err.startswith("vkray.farm: ")


def test_a_python_without_dask_is_told_what_to_install_for_it(scenes, tmp_path):
    # As a venv, pyenv or conda interpreter without Dask runs it: `distributed` cannot be imported.
    hide_dask = ("import runpy, sys; sys.modules['distributed'] = None; sys.argv[0] = 'vkray.farm'; "
                 "runpy.run_module('vkray.farm', run_name='__main__', alter_sys=True)")
    job = run(sys.executable, "-c", hide_dask, f"{scenes}/cornell.json", "-o", "x.pfm", check=False, cwd=tmp_path)
    assert job.returncode == 1, job.stderr
    assert "needs Dask's distributed" in job.stderr, job.stderr
    assert f"{sys.executable} -m pip install distributed" in job.stderr, job.stderr
    assert "Traceback" not in job.stderr, job.stderr
    assert list(tmp_path.iterdir()) == []


def test_denoise_without_pyoidn_fails_before_any_work(scenes, tmp_path):
    hide_pyoidn = ("import runpy, sys; sys.modules['pyoidn'] = None; sys.argv[0] = 'vkray.farm'; "
                   "runpy.run_module('vkray.farm', run_name='__main__', alter_sys=True)")
    job = run(sys.executable, "-c", hide_pyoidn, f"{scenes}/cornell-path.json", "-o", "x.exr", "--denoise",
              check=False, cwd=tmp_path)
    assert job.returncode == 1, job.stderr
    assert "--denoise needs Intel Open Image Denoise (pyoidn)" in job.stderr, job.stderr
    assert "Traceback" not in job.stderr and "parts" not in job.stderr, job.stderr  # no cluster was started
    assert list(tmp_path.iterdir()) == []


def commit_case(tmp_path: Path, old: dict[int, str]) -> tuple[list[Path], list[Path], Path]:
    """Three merged frames in a parts folder, ready for `_commit`, and their targets, those in `old`
    there already with that text; the last target's folder is missing, so that its rename fails."""
    parts = tmp_path / "parts"
    parts.mkdir()
    merged = [parts / f"merged{frame}" for frame in range(3)]
    for frame, file in enumerate(merged):
        file.write_text(f"new {frame}")
    targets = [tmp_path / "out.0000.pfm", tmp_path / "out.0001.pfm", tmp_path / "gone" / "out.pfm"]
    for frame, text in old.items():
        targets[frame].write_text(text)
    return merged, targets, parts


def test_outputs_are_renamed_into_place_all_or_none(tmp_path):
    # The farm's last step, the library's commit (rename_together, which tests/image_test.cpp holds
    # to more: every step, a file system without hard links, an old file that cannot be put back):
    # frames 0 and 1 are renamed into place, frame 2 cannot be (its folder is gone); frame 0's
    # earlier file is back as it was and frame 1, which was not there, is gone again.
    merged, targets, parts = commit_case(tmp_path, {0: "old 0"})
    before = os.stat(targets[0]).st_ino
    with pytest.raises(vkray.SceneError, match="out.pfm: cannot rename into place"):
        _commit(merged, targets, parts)
    assert targets[0].read_text() == "old 0" and os.stat(targets[0]).st_ino == before
    assert not targets[1].exists()
    # And when every rename succeeds, all are the new ones, and no second name is left.
    targets[2].parent.mkdir()
    for frame, file in enumerate(merged):  # the failed commit used up the frames it renamed
        file.write_text(f"new {frame}")
    _commit(merged, targets, parts)
    assert [target.read_text() for target in targets] == ["new 0", "new 1", "new 2"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gone", "out.0000.pfm", "out.0001.pfm", "parts"]


def test_a_folder_in_the_way_of_an_output_is_refused_and_left_as_it_is(tmp_path):
    # A folder that appeared where an output goes while the parts were rendered (its path was
    # checked at the start), and every other rename would succeed: the commit fails and puts back
    # what it replaced; the folder and what it holds stay where they are.
    merged, targets, parts = commit_case(tmp_path, {0: "old 0"})
    targets[2].parent.mkdir()
    targets[1].mkdir()
    (targets[1] / "kept").write_text("a user's file")
    with pytest.raises(vkray.SceneError, match="out.0001.pfm: cannot rename into place"):
        _commit(merged, targets, parts)
    assert targets[0].read_text() == "old 0"
    assert (targets[1] / "kept").read_text() == "a user's file"


def test_the_installed_package_holds_every_module_of_the_farm(tmp_path, scenes):
    # `cmake --install` lays out every .py of python/vkray, and the farm runs from there: it reads
    # its options only after importing all of its modules.
    build, cmake, site = (os.environ.get(k) for k in ("VKRAY_BUILD_DIR", "CMAKE_COMMAND", "VKRAY_PYTHON_INSTALL_DIR"))
    if not (build and cmake and site):
        pytest.fail("VKRAY_BUILD_DIR, CMAKE_COMMAND and VKRAY_PYTHON_INSTALL_DIR are set by ctest")
    prefix = tmp_path / "prefix"
    subprocess.run([cmake, "--install", build, "--prefix", str(prefix)], check=True, capture_output=True, timeout=120)
    package = prefix / site / "vkray"
    sources = sorted(p.name for p in (ROOT / "python" / "vkray").glob("*.py"))
    assert "_farm_parts.py" in sources
    assert [name for name in sources if not (package / name).is_file()] == []
    job = run(sys.executable, "-m", "vkray.farm", str(scenes / "cornell.json"), "-o", "x.pfm", "--width", "20000", check=False,
              cwd=tmp_path, env=dict(os.environ, PYTHONPATH=str(prefix / site)))
    assert job.returncode == 2, job.stderr
    assert "vkray.farm: error: --width: expected an integer from 1 to 16384, got 20000" in job.stderr, job.stderr


def test_bands_and_merge_from_python(scenes, tmp_path):
    scene = scenes / "cornell.json"
    bands = vkray.bands(scene, 3, width=64, height=48)
    assert [b[1] for b in bands] == [0, bands[0][3], bands[1][3]] and bands[-1][3] == 48
    with vkray.Renderer() as r:
        parts = []
        for i, band in enumerate(bands):
            parts.append(tmp_path / f"p{i}.exr")
            r.render_to_file(scene, parts[-1], width=64, height=48, region=band)
        whole = r.render(scene, width=64, height=48)
        r.render_to_file(scene, tmp_path / "whole.exr", width=64, height=48)
        assert r.render(scene, width=64, height=48, region="1/3").shape == (bands[1][3] - bands[1][1], 64, 3)
    # An EXR part is the data window of the full display window, to a reader that is not vkray's.
    image = oiio.ImageInput.open(str(parts[1]))
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    assert (spec.x, spec.y, spec.width, spec.height) == (0, bands[1][1], 64, bands[1][3] - bands[1][1])
    assert (spec.full_x, spec.full_y, spec.full_width, spec.full_height) == (0, 0, 64, 48)
    assert '"scene_digest"' in spec.get_string_attribute("vkray.part")
    rows = whole[bands[1][1]:bands[1][3]].astype(np.float16).astype(np.float32)
    assert np.array_equal(pixels[:, :, :3], rows)
    summary = vkray.merge(tmp_path / "m.exr", parts)
    assert summary["parts"] == 3 and not summary["mixed_devices"]
    assert (tmp_path / "m.exr").read_bytes() == (tmp_path / "whole.exr").read_bytes()
    with pytest.raises(vkray.SceneError, match="no part covers"):
        vkray.merge(tmp_path / "gap.exr", parts[:2])
    with pytest.raises(vkray.UsageError, match="expected X0,Y0,X1,Y1"):
        vkray.render(scene, width=8, height=8, region="1-2")
    with pytest.raises(vkray.UsageError, match="a region is"):
        vkray.render(scene, width=8, height=8, region=(0, 0, 4.5, 8))
    assert vkray.render(scene, width=8, height=8, region=np.array([0, 0, 4, 8])).shape == (8, 4, 3)
    assert whole.shape == (48, 64, 3)
