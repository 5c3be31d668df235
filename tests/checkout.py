"""A copy of this checkout as git tracks it, for tests that must see what a fresh clone sees.

The files are the working tree's (so uncommitted edits are tested) but only those git tracks (so a
file someone forgot to add is missing here as it would be in a clone, and scratch/, .venv, build
output and caches never come along).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def tracked_files(root: Path = ROOT) -> list[str]:
    listing = subprocess.run(
        ["git", "-C", str(root), "ls-files", "-z"], capture_output=True, check=True, timeout=60
    ).stdout
    return [name for name in listing.decode().split("\0") if name]


def copy_tracked(dest: Path, root: Path = ROOT) -> Path:
    """Copy every tracked file that exists in the working tree to ``dest`` (made); returns ``dest``."""
    for name in tracked_files(root):
        source = root / name
        if source.is_file():  # tracked but deleted in the working tree: gone from the copy too
            target = dest / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
    return dest


def build_dists(dest: Path) -> tuple[Path, Path]:
    """``python -m build`` on a tracked copy of the checkout: the sdist, then the wheel built from it
    (so a file the sdist lacks breaks the wheel too). Returns (sdist, wheel) in ``dest / "dist"``."""
    import sys

    tree = copy_tracked(dest / "tree")
    done = subprocess.run(
        [sys.executable, "-m", "build", "--outdir", str(dest / "dist"), str(tree)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    (sdist,) = (dest / "dist").glob("*.tar.gz")
    (wheel,) = (dest / "dist").glob("*.whl")
    return sdist, wheel
