"""The farm's task, run on a Dask worker: renders one band of a scene as a part file and sends the
file back. Dask sends the task by its module's name, so a worker imports this module (and vkray),
never the farm's command line."""

from __future__ import annotations

import os
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Optional

import vkray

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
