"""The documentation's pictures are the GUI tests' own: which test takes each, and the export.

``./rtmu-dev screenshots`` (``python tests/gui/doc_screenshots.py [DIR]``) runs just those tests on
their own Xvfb, as the suite does, and copies each picture to ``docs/screenshots/NAME.png`` (or DIR).
A picture therefore always shows the window as the tests last saw it work. ``tests/test_docs.py``
checks that every picture the docs and the AppStream metainfo use is listed here.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TARGET = ROOT / "docs" / "screenshots"

DOC_SHOTS: dict[str, tuple[str, str]] = {
    "window": (
        "tests/gui/test_window.py::test_connects_and_draws_the_map_walls_and_the_robot_where_the_simulator_has_it",
        "connected",
    ),
    "driving": ("tests/gui/test_window.py::test_holding_up_drives_forward_and_releasing_stops", "driving"),
    "link-lost": ("tests/gui/test_window.py::test_simulator_killed_while_driving", "link-lost"),
    "navigation": (
        "tests/gui/test_navigation_window.py::test_the_path_is_drawn_and_stop_ends_the_navigation_mid_route",
        "path-to-lab-b",
    ),
    "camera": (
        "tests/gui/test_live_video.py::test_split_view_shows_map_and_live_video_side_by_side",
        "split",
    ),
    "ptz": (
        "tests/gui/test_ptz_window.py::test_ptz_buttons_keys_and_drag_move_the_simulated_head",
        "camera-panned-left",
    ),
    "fleet": (
        "tests/gui/test_fleet_robots.py::test_three_robots_are_listed_and_drawn_each_in_its_colour",
        "fleet-three-robots/three-robots",
    ),
    "phone": (
        "tests/gui/test_handheld_window.py::test_portrait_phone_layout_fits_and_the_thumb_dpad_drives",
        "portrait-360x720",
    ),
    "alarms": (
        "tests/gui/test_handheld_window.py::test_battery_and_wifi_alarms_from_the_simulator_with_mute",
        "alarm-battery-low",
    ),
    "popups": ("tests/gui/test_popups_window.py::test_a_card_shows_the_popup_and_a_click_answers_it", "card"),
    "replay": (
        "tests/gui/test_replay_window.py::test_replay_draws_the_recorded_robot_pauses_scrubs_and_never_drives",
        "replay-window/replay-at-end",
    ),
}
"""Picture name in docs/screenshots → (the test that takes it, the label it saves it under). A test that
names its window itself (``Gui.open(…, "fleet-three-robots")``) has that name before the label."""


def picture_of(shots: Path, node: str, label: str) -> Path:
    """The PNG ``node`` saved as ``<name>-NN-<label>.png`` (the harness's naming; the name is the
    test's own unless the label says ``name/label``)."""
    name, _, label = label.rpartition("/")
    found = sorted(shots.glob(f"{name or node.rsplit('::', 1)[1]}-[0-9][0-9]-{label}.png"))
    if len(found) != 1:
        raise SystemExit(f"doc_screenshots: {node} saved {len(found)} pictures labelled {label!r} in {shots}")
    return found[0]


def export(target: Path = TARGET) -> list[Path]:
    """Run the tests that take the pictures; copy each to ``target``; the pictures written."""
    with tempfile.TemporaryDirectory(prefix="rtmu-doc-shots-") as tmp:
        shots = Path(tmp)
        env = dict(os.environ, RTMU_SCREENSHOTS=str(shots))
        for name in ("DISPLAY", "XDG_CONFIG_HOME", "RTMU_GUI_TMP"):
            env.pop(name, None)  # the run starts its own Xvfb and scratch root
        nodes = sorted({node for node, _ in DOC_SHOTS.values()})
        run = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *nodes], cwd=ROOT, env=env
        )
        if run.returncode != 0:
            raise SystemExit(f"doc_screenshots: the tests failed (exit {run.returncode}); nothing copied")
        target.mkdir(parents=True, exist_ok=True)
        written = []
        for name, (node, label) in DOC_SHOTS.items():
            out = target / f"{name}.png"
            shutil.copyfile(picture_of(shots, node, label), out)
            written.append(out)
        return written


if __name__ == "__main__":
    for path in export(Path(sys.argv[1]) if len(sys.argv) > 1 else TARGET):
        print(path)
