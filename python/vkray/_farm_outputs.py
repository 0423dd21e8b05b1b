"""The job's outputs: each frame's file name, its parts merged into it, and all the frames put in
place at the end, all or none."""

from __future__ import annotations

import os
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
