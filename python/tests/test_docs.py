"""The README and the manual in docs/ say what they show: every fenced ``sh`` and ``python`` block runs
as written, and every link between the pages leads somewhere.

A block runs as a newcomer would run it from the root of a source tree that has been built: in a
scratch copy of the tree (so that nothing it writes lands in the real one), with ``build`` a link to
the build under test (VKRAY_BUILD_DIR), and ``python3`` and ``vkray`` on the PATH naming the Python
that runs these tests and the build's command. ``sh`` blocks run in bash with ``set -e -o pipefail``,
so any line that fails fails the block. A block is left out only when an HTML comment
``<!-- not run: REASON -->`` stands just before it (among the comments that precede it): the quick
start, which builds and would run this very test, a cluster, a GPU machine.

Links are checked as GitHub renders them: a relative link must name a file or folder of the tree, and
its ``#anchor`` a heading (GitHub's slug of it) or an ``<a id>`` of the page it names."""

import os
import re
import shutil
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from conftest import ROOT

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUN_LANGUAGES = {"sh", "python"}
BLOCK_TIMEOUT_S = 120
# What a scratch copy of the tree leaves out: builds (`build` becomes a link to the one under test),
# version control, and caches.
NOT_COPIED = re.compile(r"^(build.*|\..*|__pycache__|.*\.pyc)$")

FENCE = re.compile(r"^(?P<indent> *)(?P<fence>```+|~~~+)\s*(?P<lang>[\w+-]*)[^`]*$")
COMMENT = re.compile(r"^\s*<!--(.*?)-->\s*$")
NOT_RUN = re.compile(r"^\s*not run:\s*(\S.*)$")


@dataclass
class Block:
    page: Path
    line: int  # of the opening fence, from 1
    lang: str
    text: str
    comments: list  # the HTML comments just before it, nearest last

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    @property
    def not_run_reason(self):
        for comment in self.comments:
            found = NOT_RUN.match(comment)
            if found:
                return found.group(1).strip()
        return None


def closes(line: str, fence: str) -> bool:
    stripped = line.strip()
    return len(stripped) >= len(fence) and stripped == fence[0] * len(stripped)


def fenced_blocks(page: Path) -> list:
    """Every fenced block of a Markdown page, with the HTML comment lines that precede it."""
    lines = page.read_text().splitlines()
    blocks = []
    i = 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, fence = len(opening.group("indent")), opening.group("fence")
        comments = []
        j = i - 1
        while j >= 0 and (COMMENT.match(lines[j]) or not lines[j].strip()):
            if lines[j].strip():
                comments.insert(0, COMMENT.match(lines[j]).group(1))
            j -= 1
        body = []
        k = i + 1
        while k < len(lines) and not closes(lines[k], fence):
            body.append(lines[k][indent:] if lines[k][:indent].strip() == "" else lines[k])
            k += 1
        assert k < len(lines), f"{page.relative_to(ROOT)}:{i + 1}: a fenced block that never closes"
        blocks.append(Block(page, i + 1, opening.group("lang").lower(), "\n".join(body) + "\n", comments))
        i = k + 1
    return blocks


ALL_BLOCKS = [block for page in PAGES for block in fenced_blocks(page)]
RUN_BLOCKS = [block for block in ALL_BLOCKS if block.lang in RUN_LANGUAGES and block.not_run_reason is None]


@pytest.fixture(scope="module")
def build_dir() -> Path:
    build = os.environ.get("VKRAY_BUILD_DIR")
    if not build:
        pytest.fail("VKRAY_BUILD_DIR is not set: run the Python tests through ctest")
    return Path(build).resolve()


@pytest.fixture(scope="module")
def pristine_tree(tmp_path_factory, build_dir) -> Path:
    """One copy of the source tree, copied again for each block."""
    tree = tmp_path_factory.mktemp("tree") / "vkray"
    shutil.copytree(ROOT, tree, ignore=lambda folder, names: [n for n in names if NOT_COPIED.match(n)])
    return tree


def scratch_tree(pristine: Path, build_dir: Path, where: Path) -> Path:
    tree = where / "vkray"
    shutil.copytree(pristine, tree, symlinks=True)
    (tree / "build").symlink_to(build_dir, target_is_directory=True)
    return tree


def block_environment(bin_dir: Path, build_dir: Path) -> dict:
    bin_dir.mkdir()
    python = bin_dir / "python3"  # a script, not a link: a link would lose a virtualenv's packages
    python.write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    python.chmod(0o755)
    (bin_dir / "vkray").symlink_to(Path(os.environ.get("VKRAY_EXECUTABLE", build_dir / "vkray")).resolve())
    env = dict(os.environ, MPLBACKEND="Agg", PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}")
    env.setdefault("PYTHONPATH", str(build_dir / "python"))
    return env


@pytest.mark.parametrize("block", RUN_BLOCKS, ids=[f"{b.where}-{b.lang}" for b in RUN_BLOCKS])
def test_the_block_runs_as_written(block, pristine_tree, build_dir, tmp_path):
    tree = scratch_tree(pristine_tree, build_dir, tmp_path)
    env = block_environment(tmp_path / "bin", build_dir)
    if block.lang == "sh":
        command = ["bash", "-e", "-o", "pipefail", "-c", block.text]
    else:
        command = [sys.executable, "-c", block.text]
    # A group of its own, so that what the block starts in the background ends with it.
    process = subprocess.Popen(command, cwd=tree, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    try:
        stdout, stderr = process.communicate(timeout=BLOCK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        pytest.fail(f"{block.where}: the {block.lang} block ran past {BLOCK_TIMEOUT_S} s:\n{block.text}")
    finally:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    assert process.returncode == 0, (f"{block.where}: the {block.lang} block failed with exit {process.returncode}:\n"
                                     f"{block.text}\n--- stdout:\n{stdout[-3000:]}\n--- stderr:\n{stderr[-3000:]}")


def test_every_left_out_block_says_why():
    for block in ALL_BLOCKS:
        for comment in block.comments:
            if comment.strip().startswith("not run"):
                assert NOT_RUN.match(comment), f"{block.where}: '<!--{comment}-->' gives no reason after 'not run:'"


def test_the_pages_run_their_examples():
    assert len(RUN_BLOCKS) >= 10, f"only {len(RUN_BLOCKS)} blocks would run: are the pages where the test looks?"


# --- links -----------------------------------------------------------------------------------------

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_TARGET = re.compile(r"<(?:a|img)\b[^>]*\b(?:href|src)=\"([^\"]+)\"")
HTML_ANCHOR = re.compile(r"<a\b[^>]*\b(?:id|name)=\"([^\"]+)\"")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def prose(page: Path, inline_code: bool = False) -> str:
    """The page without its fenced blocks (and without its inline code, unless asked), where link
    syntax is only text."""
    kept, fence = [], None
    for line in page.read_text().splitlines():
        opening = FENCE.match(line)
        if fence is None and opening:
            fence = opening.group("fence")
            kept.append("")
        elif fence is not None and closes(line, fence):
            fence = None
            kept.append("")
        else:
            kept.append("" if fence else line if inline_code else re.sub(r"`[^`]*`", "``", line))
    return "\n".join(kept)


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: the rendered text, lower case, without punctuation but for '-'
    and '_', spaces made hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text
    text = re.sub(r"<[^>]+>", "", text).replace("`", "")
    text = text.replace("*", "")
    return re.sub(r"[^\w\- ]", "", text.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set:
    found, seen = set(), {}
    for line in prose(page, inline_code=True).splitlines():
        heading = HEADING.match(line)
        if heading:
            base = slug(heading.group(2))
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
    found.update(HTML_ANCHOR.findall(page.read_text()))
    return found


def links(page: Path):
    text = prose(page)
    for number, line in enumerate(text.splitlines(), start=1):
        for target in LINK.findall(line) + HTML_TARGET.findall(line):
            yield number, target


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES])
def test_links_lead_somewhere(page):
    broken = []
    for line, target in links(page):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # https:, mailto:: outside the tree
            continue
        path, _, fragment = target.partition("#")
        destination = (page.parent / path).resolve() if path else page
        where = f"{page.relative_to(ROOT)}:{line}: ({target})"
        if not destination.is_relative_to(ROOT):
            broken.append(f"{where} leads out of the source tree")
        elif not destination.exists():
            broken.append(f"{where} names no file")
        elif fragment:
            if destination.suffix != ".md":
                broken.append(f"{where} has an anchor into a file that is not a Markdown page")
            elif fragment not in anchors(destination):
                broken.append(f"{where}: {destination.relative_to(ROOT)} has no heading or <a id> '{fragment}'")
    assert not broken, "\n".join(broken)


def test_slugs_follow_github():
    assert slug("Rendering across machines: regions, `vkray merge`, Dask and Slurm") == \
        "rendering-across-machines-regions-vkray-merge-dask-and-slurm"
    assert slug("Parity: GPU against the CPU reference") == "parity-gpu-against-the-cpu-reference"
    assert slug("First-hit passes (AOVs) and OpenEXR") == "first-hit-passes-aovs-and-openexr"
    assert slug("What the time goes to on llvmpipe") == "what-the-time-goes-to-on-llvmpipe"
    assert slug("`vkray_core` and **bold**") == "vkray_core-and-bold"
