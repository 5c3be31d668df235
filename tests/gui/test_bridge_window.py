"""View ▸ Foxglove bridge: the window's robot on a Foxglove WebSocket server, publishing only.

The real window connects to the simulator; the menu's action starts the bridge (on a free
port here, 8765 in use); a WebSocket client (``websockets``) gets the map the window already
had and live poses; client publishing is not advertised, so Foxglove cannot drive from the
window. Unchecking it ends the server.
"""

from __future__ import annotations

import pytest

from recorder.foxglove_client import FoxgloveClient
from recorder.poses import _position
from rtmu.recorder import topics
from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

pytestmark = pytest.mark.gui


sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def test_the_window_serves_its_robot_to_foxglove_and_never_lets_it_drive(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    window.foxglove.port = 0  # any free port: 8765 may be taken on this machine
    window.activate_action("win.foxglove", None)  # the View menu's check item
    pump(lambda: window.foxglove.bridge is not None, 5, "the bridge to start")
    bridge = window.foxglove.bridge
    assert bridge is not None
    pump(
        lambda: (
            "Foxglove bridge on ws://"
            in " ".join(window.banners.text(t) or "" for t in window.banners.topics())
        ),
        3,
        "its banner",
    )
    gui.shot("foxglove-bridge-on")
    with FoxgloveClient(f"ws://127.0.0.1:{bridge.port}") as client:
        client.until(lambda: bool(client.server_info))
        assert "clientPublish" not in client.server_info.get("capabilities", [])
        client.subscribe(topics.POSE, topics.MAP)
        client.until(lambda: bool(client.of(topics.MAP)), 5)
        sim.call(lambda: sim.server.world.ratio_drive(50.0, 0.0, 50.0))  # type: ignore[union-attr]
        for _ in range(20):
            client.pump(0.05)
            idle(0.05)
        sim.call(lambda: sim.server.world.stop())  # type: ignore[union-attr]
        poses = {_position(m.data) for m in client.of(topics.POSE)}
        assert len(poses) > 3
    window.activate_action("win.foxglove", None)
    pump(lambda: window.foxglove.bridge is None, 5, "the bridge to stop")
