"""The job's outputs: each frame's file name, its parts merged into it, and all the frames put in
place at the end, all or none, so that no output is ever missing."""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import sys
from pathlib import Path
from typing import Optional

import vkray

# What os.link answers where a file cannot have another hard link: the file system has none (Linux's
# vfat and exfat answer EPERM, FUSE and network file systems often EOPNOTSUPP or ENOSYS), the file is
# at its file system's limit of links (EMLINK), or, for EPERM again, the kernel's protected_hardlinks
# refuses a link to another user's file.
_NO_HARD_LINK = {errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.ENOSYS, errno.EMLINK}


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
    """Renames each merged image over its target, all or none, so that a target that was there is
    there at every moment, as its old file or its new one.

    The old file is kept first under a second name beside the parts' `folder` (beside the targets,
    so on their file system) as a hard link, and os.replace then puts the new file over the target
    in one step. When a later rename fails, each earlier target is put back from its second name,
    again in one step, and a target that was not there before is removed; should putting one back
    fail too, the error names where its old file is. A target that is a folder is refused, never
    replaced.

    Where the target cannot have another hard link (the file system has none, as vfat and some FUSE
    and network file systems; see _NO_HARD_LINK), the old file itself is renamed to its second name
    instead, as the library's AtomicFile::commit_together does, and between that rename and the next
    the target does not exist: a SIGKILL there leaves the old file only under its second name."""
    done = []  # (target, its old file's second name, or None)
    try:
        for frame, (file, target) in enumerate(zip(merged, targets)):
            kept = None
            if os.path.lexists(target):
                kept = folder.with_name(f"{folder.name}.previous{frame:05d}")
                _keep(target, kept)
            done.append((target, kept))
            os.replace(file, target)
    except BaseException as error:
        stranded = _put_back(done)
        if stranded and isinstance(error, OSError):
            raise OSError("; ".join([str(error), *stranded])) from error
        raise
    for _, kept in done:
        if kept is not None:
            with contextlib.suppress(OSError):
                kept.unlink()


def _keep(target: Path, kept: Path) -> None:
    """Keeps the file at `target` (a symbolic link as the link) at `kept` too: as a hard link, so
    that it stays at `target`; else moved there."""
    if stat.S_ISDIR(os.lstat(target).st_mode):
        raise IsADirectoryError(errno.EISDIR, "a folder is in the way of the output", str(target))
    try:
        os.link(target, kept, follow_symlinks=False)
    except OSError as e:
        if e.errno not in _NO_HARD_LINK:
            raise
        os.replace(target, kept)


def _put_back(done: list[tuple[Path, Optional[Path]]]) -> list[str]:
    """Undoes the renames of `done`, the last first: each old file back at its target, each target
    that was not there removed. Returns what could not be put back, as "the old TARGET is kept as NAME"."""
    stranded = []
    for target, kept in reversed(done):
        try:
            if kept is not None:
                os.replace(kept, target)
                kept.unlink(missing_ok=True)  # still there when the target was never replaced: one file
            else:
                target.unlink(missing_ok=True)
        except OSError:
            if kept is not None and os.path.lexists(kept):
                stranded.append(f"the old {target} is kept as {kept}")
    return stranded
