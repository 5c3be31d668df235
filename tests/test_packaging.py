"""``python -m build``: an sdist and a wheel with everything RTMU reads at run time, and nothing GPL.

The wheel must carry every module, the maps ``--demo`` and ``rtmu sim`` serve, the desktop entry, icon
and AppStream metainfo, and the ``rtmu`` command. ARIA's maps and the captured ARIA sessions in
``tests/data`` are GPL-2 test data: no file of either may be in the wheel or the sdist, under any name.
(tests/gui/test_installed_wheel.py installs the wheel and runs it.)
"""

from __future__ import annotations

import hashlib
import tarfile
import zipfile
from email.parser import HeaderParser
from pathlib import Path

from checkout import tracked_files
from rtmu import __version__
from testdata import TEST_DATA

ROOT = Path(__file__).resolve().parents[1]


def wheel_files(wheel: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(wheel) as archive:
        return {name: archive.read(name) for name in archive.namelist() if not name.endswith("/")}


def sdist_files(sdist: Path) -> dict[str, bytes]:
    out: dict[str, bytes] = {}
    with tarfile.open(sdist) as archive:
        for member in archive.getmembers():
            if member.isfile():
                handle = archive.extractfile(member)
                assert handle is not None
                out[member.name.split("/", 1)[1]] = handle.read()
    return out


def digests(files: dict[str, bytes]) -> dict[str, str]:
    return {hashlib.sha256(data).hexdigest(): name for name, data in files.items()}


def gpl_test_data() -> dict[str, str]:
    return {
        hashlib.sha256(p.read_bytes()).hexdigest(): str(p.relative_to(ROOT))
        for p in TEST_DATA.rglob("*")
        if p.is_file() and p.name != "README.md"
    }


def test_the_wheel_holds_every_module_and_what_the_app_reads_at_run_time(
    built_dists: tuple[Path, Path],
) -> None:
    _, wheel = built_dists
    assert wheel.name == f"rtmu-{__version__}-py3-none-any.whl"
    files = wheel_files(wheel)
    modules = {name.removeprefix("src/") for name in tracked_files() if name.startswith("src/rtmu/")}
    missing = sorted(modules - files.keys())
    assert not missing, f"tracked in src/ but not in the wheel: {missing}"
    for data in (
        "rtmu/data/maps/arena.map",
        "rtmu/data/maps/office.map",
        "rtmu/data/desktop/io.github.rtmu.Rtmu.desktop",
        "rtmu/data/desktop/io.github.rtmu.Rtmu.svg",
        "rtmu/data/desktop/io.github.rtmu.Rtmu.metainfo.xml",
        "rtmu/data/locale/de/LC_MESSAGES/rtmu.mo",
        "rtmu/py.typed",
    ):
        assert files[data] == (ROOT / "src" / data).read_bytes(), data
    info = f"rtmu-{__version__}.dist-info"
    assert "rtmu = rtmu.cli:main" in files[f"{info}/entry_points.txt"].decode()
    metadata = HeaderParser().parsestr(files[f"{info}/METADATA"].decode())
    assert metadata["Name"] == "rtmu" and metadata["Version"] == __version__
    assert metadata["License-Expression"] == "MIT"
    assert files[f"{info}/licenses/LICENSE"] == (ROOT / "LICENSE").read_bytes()
    requires = " ".join(metadata.get_all("Requires-Dist") or [])
    for needed in ("PyGObject", "pycairo", "numpy", "argparse-manpage", "shtab"):
        assert needed in requires, needed
    assert not [n for n in files if n.startswith(("tests/", "bench/", "docs/"))]


def test_neither_the_wheel_nor_the_sdist_carries_aria_gpl_test_data(built_dists: tuple[Path, Path]) -> None:
    gpl = gpl_test_data()
    assert len(gpl) >= 13, "tests/data should hold the ARIA maps and captures"
    for dist, files in (
        (built_dists[1], wheel_files(built_dists[1])),
        (built_dists[0], sdist_files(built_dists[0])),
    ):
        carried = {gpl[h]: name for h, name in digests(files).items() if h in gpl}
        assert not carried, f"{dist.name} carries GPL test data: {carried}"
        assert not [n for n in files if "aria-maps" in n or n.endswith(".pcap")], dist.name


def test_the_sdist_builds_the_package_and_says_what_it_is(built_dists: tuple[Path, Path]) -> None:
    sdist, _ = built_dists
    files = sdist_files(sdist)
    for name in (
        "pyproject.toml",
        "README.md",
        "LICENSE",
        "src/rtmu/cli.py",
        "src/rtmu/data/maps/office.map",
    ):
        assert files[name] == (ROOT / name).read_bytes(), name
    assert not [n for n in files if n.startswith("tests/")]
