"""The job's outputs: each frame's file name, its parts merged into it (and then denoised, with
--denoise), and all the frames put in place at the end, all or none, so that no output is ever
missing."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import vkray
from vkray import _denoise


def _frame_output(output: Path, frame: int, frames: int) -> Path:
    """OUT for one frame; with several, the frame's number before the suffix: out.exr -> out.0001.exr."""
    return output if frames == 1 else output.with_name(f"{output.stem}.{frame:04d}{output.suffix}")


def _merge_frames(parts: list[list[Path]], folder: Path, suffix: str) -> list[Path]:
    """Merges each frame's part files into a file of its own in `folder` (of the output's type,
    `suffix`); returns those files, frame by frame."""
    merged = []
    for frame, files in enumerate(parts):
        merged.append(folder / f"merged{frame:05d}{suffix}")
        summary = vkray.merge(merged[-1], files)
        if summary["mixed_devices"]:
            print("vkray.farm: warning: the parts were rendered on more than one device: the image agrees with a "
                  "single render within parity, not bit for bit", file=sys.stderr)
    return merged


def _denoise_frames(merged: list[Path], folder: Path, suffix: str, passes: Sequence[str], exr_float: bool,
                    say: Callable[[str], None]) -> list[Path]:
    """Denoises each merged frame (a float EXR that holds the guides, _denoise.GUIDES) with Intel
    Open Image Denoise into a file of its own in `folder`, of the output's type (`suffix`), that
    keeps `passes` beside the denoised colour; returns those files, frame by frame. The whole frame is
    denoised at once: the denoiser looks across the bands' edges."""
    denoised = []
    for frame, file in enumerate(merged):
        arrays, _ = vkray._vkray._read_image(file)
        start = time.perf_counter()
        color = _denoise.denoise(arrays["color"], *(arrays[guide] for guide in _denoise.GUIDES))
        say(f"denoised frame {frame} ({color.shape[1]}x{color.shape[0]}) in {time.perf_counter() - start:.2f} s")
        denoised.append(folder / f"denoised{frame:05d}{suffix}")
        vkray._vkray._write_image(denoised[-1], {**{name: arrays[name] for name in passes}, "color": color}, exr_float)
    return denoised


def _commit(merged: list[Path], targets: list[Path], folder: Path) -> None:
    """Renames each merged image over its target, all or none, with the library's own commit
    (rename_together, base/atomic_file.h): an output that was there is there at every moment, as its
    old file or its new one, its old file kept meanwhile as a hard link beside the parts' `folder`
    (on the targets' file system, and not inside the folder, which is removed at the end) and put back
    if a later rename fails; a folder in an output's place is never replaced. Raises vkray.SceneError
    naming the output that could not be put in place, and where an old file is kept that could not be
    put back."""
    vkray._vkray._rename_together([(file, target, folder.with_name(f"{folder.name}.previous{frame:05d}"))
                                   for frame, (file, target) in enumerate(zip(merged, targets))])
