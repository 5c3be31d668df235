"""constraints.txt pins every package ``pip install -e '.[dev]'`` brings, at the version tested.

The set-up installs with ``-c constraints.txt`` so a fresh checkout gets what the suite ran with, not
whatever is newest that day. These tests walk the real dependency tree of the installed ``rtmu[dev]``
and fail when a package is missing from the pins or the venv drifted from them.
"""

from __future__ import annotations

import re
import tomllib
from importlib import metadata
from pathlib import Path

from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]


def pins() -> dict[str, str]:
    out: dict[str, str] = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, _, version = line.partition("==")
            assert version, f"constraints.txt: {line!r} is not an exact pin"
            out[canonicalize_name(name)] = version
    return out


def needed(root: str = "rtmu", extras: tuple[str, ...] = ("dev",)) -> set[str]:
    """Every distribution the installed ``root[extras]`` requires, transitively, on this Python."""
    seen: set[str] = set()
    todo = [(root, extras)]
    while todo:
        name, wanted = todo.pop()
        for text in metadata.requires(name) or []:
            req = Requirement(text)
            if req.marker and not any(
                req.marker.evaluate({**default_environment(), "extra": extra}) for extra in ("", *wanted)
            ):
                continue
            key = canonicalize_name(req.name)
            if key not in seen:
                seen.add(key)
                todo.append((req.name, tuple(req.extras)))
    return seen


def test_every_needed_package_is_pinned_at_the_installed_version() -> None:
    pinned = pins()
    wanted = needed()
    assert {"numpy", "pillow", "pycairo", "pygobject", "keyring", "pytest", "hypothesis", "ruff"} <= wanted
    missing = sorted(wanted - pinned.keys())
    assert not missing, f"not in constraints.txt: {missing}"
    drifted = {n: (pinned[n], metadata.version(n)) for n in wanted if metadata.version(n) != pinned[n]}
    assert not drifted, f"constraints.txt vs .venv (pinned, installed): {drifted}"
    assert "rtmu" not in pinned


def test_pyproject_keeps_ranges_and_setup_installs_with_the_pins() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    for text in [*project["dependencies"], *project["optional-dependencies"]["dev"]]:
        assert "==" not in text, f"pyproject.toml should keep a range, not a pin: {text}"
    setup = (ROOT / "scripts" / "setup.sh").read_text()
    assert re.search(r'pip install .*-c "\$CONSTRAINTS" -e', setup)
    assert "CONSTRAINTS=constraints.txt" in setup
    assert re.search(r"sha256sum pyproject.toml \"\$CONSTRAINTS\"", setup), "the stamp must hash the pins"
