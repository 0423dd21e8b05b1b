"""The job's outputs: each frame's file name, its parts merged into it, and all the frames put in
place at the end, all or none, so that no output is ever missing."""

from __future__ import annotations

import sys
from pathlib import Path

import vkray


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
