"""The shipped desktop entry and AppStream metainfo pass the freedesktop validators and agree with RTMU.

``appstreamcli validate`` and ``desktop-file-validate`` are what distributions and software centres run;
here they run on every test run (CI included). The metainfo's id, launchable and newest release must
match the desktop file and ``rtmu.__version__``.
"""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

from rtmu import __version__
from rtmu.package_data import APP_ID, DESKTOP_DIR

METAINFO = DESKTOP_DIR / f"{APP_ID}.metainfo.xml"
DESKTOP = DESKTOP_DIR / f"{APP_ID}.desktop"


def validate(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["appstreamcli", "validate", "--no-net", str(path)], capture_output=True, text=True, timeout=60
    )


def test_metainfo_passes_appstreamcli() -> None:
    done = validate(METAINFO)
    assert done.returncode == 0, done.stdout + done.stderr


def test_appstreamcli_here_does_fail_a_broken_metainfo(tmp_path: Path) -> None:
    broken = tmp_path / METAINFO.name
    broken.write_text(METAINFO.read_text().replace("<id>io.github.rtmu.Rtmu</id>", "<id>not an id!</id>"))
    assert validate(broken).returncode != 0


def test_desktop_file_passes_desktop_file_validate() -> None:
    done = subprocess.run(["desktop-file-validate", str(DESKTOP)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and not done.stdout.strip(), done.stdout + done.stderr


def test_metainfo_agrees_with_the_desktop_file_the_version_and_the_screenshots() -> None:
    component = ET.parse(METAINFO).getroot()
    assert component.findtext("id") == APP_ID
    assert component.findtext("launchable[@type='desktop-id']") == DESKTOP.name
    newest = component.find("releases/release")
    assert newest is not None and newest.get("version") == __version__
    controls = {c.text for c in component.findall("supports/control")}
    assert controls == {"keyboard", "pointing", "touch", "gamepad"}
    assert "Icon=" + APP_ID in DESKTOP.read_text() and (DESKTOP_DIR / f"{APP_ID}.svg").is_file()
