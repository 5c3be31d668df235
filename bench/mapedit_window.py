"""The real window applying a map edit, measured from inside its own process (under the bench's Xvfb).

``python -m bench.mapedit_window PORT REPEAT`` opens RTMU's window on the simulator at PORT (serving a
large map), opens Server ▸ Edit the map…, and REPEAT times adds one goal to the draft and presses
Apply (``MapEditWindow.apply``, what the button calls). For each it times, from Apply: the server's
verdict shown in the window, and the first complete frame of the map stage showing the reloaded map
(``MapStage.on_first_map_frame``, which fires once per new map). Prints one JSON object.
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import gi

gi.require_version("Gtk", "4.0")

from bench import video_window  # noqa: E402
from rtmu.model.observables import MapPhase, Phase  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402

TIMEOUT = 120.0


def pump(condition: Any, timeout: float = TIMEOUT) -> None:
    video_window.pump(condition, timeout)


def main(argv: list[str]) -> int:
    port, repeat = int(argv[0]), int(argv[1])
    settings = Path(tempfile.mkdtemp(prefix="rtmu-bench-mapedit-")) / "settings.toml"
    app = RtmuApplication(
        GuiOptions(host="127.0.0.1", port=port, settings_path=settings, persist=False, connect=None)
    )
    app.register(None)
    app.activate()
    pump(lambda: app.window is not None and app.window.get_mapped())
    window = app.window
    assert window is not None
    window.set_default_size(1024, 600)
    frames: list[float] = []
    window.stage.on_first_map_frame = frames.append
    pump(lambda: window.model.connection.value.phase is Phase.CONNECTED)
    pump(lambda: window.model.map.value.state is MapPhase.READY and bool(frames))
    window.commissioning.edit_map()
    editor = window.commissioning.map_edit
    assert editor is not None
    pump(lambda: editor.draft is not None and editor.get_mapped())
    verdicts: list[float] = []
    redrawn: list[float] = []
    for i in range(repeat):
        editor.run_edit(lambda d, i=i: d.add_goal(f"Window {i}", 2000 + i, 1000, 90))
        shown, applied = len(frames), editor.applied
        t0 = time.perf_counter()
        editor.apply()
        pump(lambda applied=applied: editor.applied > applied)
        verdicts.append(time.perf_counter() - t0)
        pump(lambda shown=shown: len(frames) > shown)
        redrawn.append(frames[-1] - t0)
        goals = window.model.navigation.value.goals
        if f"Window {i}" not in goals:
            raise RuntimeError(f"the reloaded map lacks the bench's goal: {goals[:5]}…")
    print(
        json.dumps(
            {
                "verdict_s": statistics.median(verdicts),
                "redrawn_s": statistics.median(redrawn),
                "all_redrawn_s": redrawn,
            }
        ),
        flush=True,
    )
    editor.close()
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
