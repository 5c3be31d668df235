"""The simulated camera head as a client sees it: the picture follows pan and zoom.

Over loopback, through the wire: ``setCameraAbsCam1`` / ``setCameraRelCam1`` move the head,
``getCameraDataCam1`` reports it, and ``getPictureCam1`` shows it — a short wall straight
ahead leaves the picture when the head pans away, comes back when it pans back, and fills
more of the picture when the head zooms in.
"""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from rtmu.protocol.payloads.camera import CameraData, Picture, SetCameraAbs, SetCameraRel

from .test_sensors import _start, _wall_rows
from .wire import WireClient, run

SHORT_WALL = """2D-Map
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
LINES
9000 -1000 9000 1000
DATA
"""


async def _picture(c: WireClient) -> np.ndarray:
    frame = Picture.decode((await c.ask("getPictureCam1"))[0])
    return np.asarray(Image.open(io.BytesIO(frame.jpeg)).convert("RGB")).astype(int)


async def _head(c: WireClient) -> tuple[float, float, float]:
    d = CameraData.decode((await c.ask("getCameraDataCam1"))[0])
    return (d.pan, d.tilt, d.zoom)


HEAD_TURNS = 2.5
"""Simulated seconds for any move to end: the head turns at the VC-C4's speeds (180° of pan in 2 s),
and the simulator renders at most one frame a frame period."""


def test_pan_and_zoom_change_the_picture(tmp_path):
    path = tmp_path / "short-wall.map"
    path.write_text(SHORT_WALL)

    async def scenario() -> None:
        server, c = await _start(path)
        ahead = await _picture(c)
        assert 20 < _wall_rows(ahead.astype(np.uint8)) < 100  # the wall is in the middle of the view

        c.once("setCameraAbsCam1", SetCameraAbs(60, 0, 0).encode())
        await c.barrier()
        await server.advance(HEAD_TURNS)
        assert await _head(c) == (60.0, 0.0, 0.0)
        left = await _picture(c)
        assert np.abs(left - ahead).mean() > 3  # the wall has left the picture
        centre = slice(100, 140), slice(140, 180)
        assert np.abs(left[centre] - ahead[centre]).mean() > 20

        c.once("setCameraRelCam1", SetCameraRel(-60, 0).encode())
        await c.barrier()
        await server.advance(HEAD_TURNS)
        assert await _head(c) == (0.0, 0.0, 0.0)
        back = await _picture(c)
        assert np.abs(back - ahead).mean() < 2  # the same view again

        c.once("setCameraAbsCam1", SetCameraAbs(0, 0, 60).encode())
        await c.barrier()
        await server.advance(HEAD_TURNS)
        zoomed = await _picture(c)
        assert _wall_rows(zoomed.astype(np.uint8)) > 2 * _wall_rows(ahead.astype(np.uint8))

        c.once("setCameraAbsCam1", SetCameraAbs(0, 20, 0).encode())
        await c.barrier()
        await server.advance(HEAD_TURNS)
        up = await _picture(c)
        assert np.abs(up - ahead).mean() > 8  # tilting moves the horizon
        await c.close()
        await server.stop()

    run(scenario())


WALL_ON_THE_RIGHT = """2D-Map
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
LINES
-6000 -2500 6000 -2500
DATA
"""


def test_a_positive_pan_turns_the_camera_right_as_arias_does(tmp_path):
    """ARIA's camera handler looks at a goal with ``pan = -delta heading``: positive pan is clockwise."""
    path = tmp_path / "right-wall.map"
    path.write_text(WALL_ON_THE_RIGHT)

    async def scenario() -> None:
        server, c = await _start(path)
        rows = {}
        for pan in (90.0, -90.0):
            c.once("setCameraAbsCam1", SetCameraAbs(pan, 0, 0).encode())
            await c.barrier()
            await server.advance(HEAD_TURNS)
            rows[pan] = _wall_rows((await _picture(c)).astype(np.uint8))
        assert rows[90.0] > 40  # the wall on the robot's right fills the middle of the view
        assert rows[-90.0] < rows[90.0] / 4  # to the left there is nothing near
        await c.close()
        await server.stop()

    run(scenario())
