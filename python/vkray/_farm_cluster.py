"""The cluster a job runs on: Dask's distributed present in this Python, a client of the scheduler
at --scheduler or of a LocalCluster started here, the workers in it that declare a GPU, and the
cluster closed in bounded time at the end, with any worker process that does not answer ended."""

from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import sys
from pathlib import Path
from typing import Any, Optional

from ._farm_errors import _ClusterError, _MissingPackage, _Usage

# How long closing the client, and then the LocalCluster, may take.
_CLOSE_SECONDS = 20


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
    raise _MissingPackage(f"the farm needs Dask's distributed, which {sys.executable} cannot import; {advice}")


def _gpu_addresses(workers: dict[str, Any]) -> list[str]:
    """The workers (scheduler_info()["workers"]) that declare a GPU."""
    return [address for address, w in workers.items() if w.get("resources", {}).get("GPU", 0) >= 1]


def _gpu_workers(client: Any) -> int:
    return len(_gpu_addresses(client.scheduler_info()["workers"]))


def _connect(scheduler: Optional[str], workers: int, timeout: float,
             workspace: Optional[Path]):  # -> (Client, cluster or None)
    """A client of the scheduler at `scheduler`, reached and given a worker with a GPU within
    `timeout` seconds, or without one of a LocalCluster of `workers` processes started here, whose
    workers keep their files in `workspace`."""
    import distributed

    if scheduler:
        import dask

        try:
            # The connection's own timeout (30 s in Dask's configuration) bounds each attempt.
            with dask.config.set({"distributed.comm.timeouts.connect": f"{timeout}s"}):
                client = distributed.Client(scheduler, timeout=f"{timeout}s")
        except OSError as e:
            raise _ClusterError(f"cannot reach the scheduler at {scheduler}: {e}") from None
        except ValueError as e:
            # Not an address at all: a bad option value, which is usage (2) on every face.
            raise _Usage(f"--scheduler {scheduler}: {e}") from None
        try:
            client.wait_for_workers(1, timeout=timeout)
        except Exception:
            client.close()
            raise _ClusterError(f"no worker joined the scheduler at {scheduler} within {timeout:g} s") from None
        if not _gpu_workers(client):
            client.close()
            raise _ClusterError(f"no worker of the scheduler at {scheduler} declares a GPU: start workers with "
                                f"`dask worker {scheduler} --resources GPU=1`")
        return client, None
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       resources={"GPU": 1}, dashboard_address=None,
                                       silence_logs=logging.ERROR, local_directory=str(workspace))
    try:
        return distributed.Client(cluster), cluster
    except BaseException:
        _close(None, cluster)
        raise


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
