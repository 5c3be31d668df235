"""Sonar, camera and Wi-Fi as a client sees them, over loopback."""

from __future__ import annotations

import io
import math

import numpy as np
from PIL import Image

from rtmu.protocol.payloads.camera import Picture, VideoFrame, VideoRequest, VideoSize
from rtmu.protocol.payloads.drawings import DrawingListPacket
from rtmu.protocol.payloads.drive import MoveDist, TurnToHeading
from rtmu.protocol.payloads.sensors import (
    RangeDeviceReadings,
    SensorCurrentRequest,
    SensorList,
    SensorReadings,
)
from rtmu.protocol.payloads.strings import Strings, StringsInfo
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.camera import Camera
from rtmu.sim.geometry import Obstacles

from .wire import WireClient, run


async def _start(map_path, **kw):
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path, **kw))
    await server.start()
    return server, await WireClient().open(server.port)


async def _jog(server: SimServer, c: WireClient, name: str, payload: bytes, seconds: float = 6.0) -> None:
    c.once(name, payload)
    await c.barrier()
    await server.advance(seconds)


WALL_AHEAD = """2D-Map
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
LINES
2000 -4000 2000 4000
DATA
"""


def test_sonar_reads_a_wall_ahead_and_nothing_in_open_space(tmp_path):
    path = tmp_path / "wall.map"
    path.write_text(WALL_AHEAD)

    async def scenario() -> None:
        server, c = await _start(path)
        assert SensorList.decode((await c.ask("getSensorList"))[0]).names == ("sim_lms2xx_1", "sonar")
        req = SensorCurrentRequest(("sonar", "nosuch")).encode()
        first, missing = (SensorReadings.decode(p) for p in await c.ask("getSensorCurrent", req, count=2))
        assert missing == SensorReadings("nosuch", (), exists=False)
        # Only the discs facing the wall echo (global mm, on the wall); behind the robot is open space.
        assert first.name == "sonar" and 4 <= len(first.readings) <= 8
        assert all(x == 2000 for x, _ in first.readings)
        ahead = min(math.hypot(x, y) for x, y in first.readings)
        assert 1990 <= ahead <= 2100
        # Nearer after driving 1 m towards it.
        await _jog(server, c, "moveDist", MoveDist(1000).encode())
        after = SensorReadings.decode((await c.ask("getSensorCurrent", req, count=2))[0])
        near = min(math.hypot(x - server.robot.x, y - server.robot.y) for x, y in after.readings)
        assert near < ahead - 900
        # The same echoes through ARIA's drawing for MobileEyes.
        drawings = [DrawingListPacket.decode(p) for p in await c.ask("getDrawingList", count=3)]
        assert [d.drawing.name for d in drawings[:2]] == ["sim_lms2xx_1Current", "sonarCurrent"]
        assert drawings[2].end_of_reply
        sonar = RangeDeviceReadings.decode((await c.ask("sonarCurrent"))[0])
        assert sorted(sonar.readings) == sorted(after.readings)
        # Turned round, the wall is behind: the rear discs see it and the front ones see nothing.
        await _jog(server, c, "turnToHeading", TurnToHeading(180).encode())
        turned = SensorReadings.decode((await c.ask("getSensorCurrent", req, count=2))[0])
        assert turned.readings and all(x == 2000 for x, _ in turned.readings)
        await c.close()
        await server.stop()

    run(scenario())


def _wall_rows(picture: np.ndarray) -> int:
    """Rows of the centre column painted with the wall's colour (the colour at the horizon)."""
    col = picture[:, picture.shape[1] // 2].astype(int)
    horizon = col[picture.shape[0] // 2]
    return int((np.abs(col - horizon).sum(axis=1) <= 12).sum())


FAR_WALL = WALL_AHEAD.replace("2000 -4000 2000 4000", "9000 -9000 9000 9000")


def test_camera_sends_valid_jpegs_at_both_sizes_and_a_nearer_wall_is_bigger_and_brighter(tmp_path):
    path = tmp_path / "far-wall.map"
    path.write_text(FAR_WALL)

    async def scenario() -> None:
        server, c = await _start(path)
        size = VideoSize.decode((await c.ask("videoSize"))[0])
        assert (size.width, size.height) == (320, 240)
        frames = {}
        for label, seconds in (("far", 0.0), ("near", 20.0)):
            if seconds:
                await _jog(server, c, "moveDist", MoveDist(5000).encode(), seconds)
            frame = VideoFrame.decode((await c.ask("sendVideo", VideoRequest(90).encode()))[0])
            image = Image.open(io.BytesIO(frame.jpeg))
            assert image.format == "JPEG" and image.size == (320, 240) == (frame.width, frame.height)
            assert frame.trailing == b"\x5a\xa5"  # forwarded video's two extra bytes, as serverDemo
            frames[label] = np.asarray(image.convert("RGB"))
        assert _wall_rows(frames["near"]) > 1.5 * _wall_rows(frames["far"])
        centre = slice(100, 140), slice(140, 180)
        assert frames["near"][centre].mean() > frames["far"][centre].mean() + 10
        c.once("SimulatorVideo640x480")
        await c.barrier()
        size = VideoSize.decode((await c.ask("videoSize"))[0])
        assert (size.width, size.height) == (640, 480)
        big = Picture.decode((await c.ask("getPictureCam1"))[0])
        assert Image.open(io.BytesIO(big.jpeg)).size == (640, 480) == (big.width, big.height)
        assert len(big.jpeg) < 31988
        await c.close()
        await server.stop()

    run(scenario())


def test_renderer_wall_height_is_inverse_to_distance():
    """Below the horizon the wall covers camera height × focal length / distance rows."""
    size = (320, 240)
    wall = Camera(Obstacles(np.array([[3000, -5000, 3000, 5000]])))
    empty = Camera(Obstacles(np.zeros((0, 4))))

    def rows_below_horizon(x: float) -> int:
        a, b = wall.render(x, 0, 0, size), empty.render(x, 0, 0, size)
        column = np.abs(a[:, 160].astype(int) - b[:, 160]).sum(axis=1) > 0
        return int(column[120:].sum())

    near, far = rows_below_horizon(1000), rows_below_horizon(0)
    # Lens 100 mm ahead of the centre: 1900 mm and 2900 mm from the wall.
    assert abs(near / far - 2900 / 1900) < 0.05


CORRIDOR = """2D-Map
Cairn: AccessPoint 0 0 0.000000 "" ICON "Access point"
Cairn: RobotHome 1000 0 0.000000 "" ICON "Home"
LINES
-500 -1500 30000 -1500
-500 1500 30000 1500
-500 -1500 -500 1500
12000 -1500 12000 -500
12000 500 12000 1500
DATA
"""


def _strings(c: WireClient, info: StringsInfo, payload: bytes) -> dict[str, str]:
    return dict(zip((i.label for i in info.items), Strings.decode(payload).values, strict=True))


def test_wifi_strings_fall_with_distance_and_walls(tmp_path):
    path = tmp_path / "corridor.map"
    path.write_text(CORRIDOR)

    async def scenario() -> list[dict[str, str]]:
        server, c = await _start(path)
        info = StringsInfo.decode((await c.ask("getStringsInfo"))[0])
        labels = [i.label for i in info.items]
        assert {"Wireless Link Quality", "Wireless Link Signal", "CPU Use"} <= set(labels)
        seen = [_strings(c, info, (await c.ask("getStrings"))[0])]
        for distance in (4000, 6000):  # to x = 5000, then through the doorway wall at 12000 to 11000
            await _jog(server, c, "moveDist", MoveDist(distance).encode(), 30.0)
            seen.append(_strings(c, info, (await c.ask("getStrings"))[0]))
        await _jog(server, c, "turnToHeading", TurnToHeading(0).encode(), 3.0)
        c.request("getStrings", 1000)
        await c.wait_for("getStrings", 4)
        await c.close()
        await server.stop()
        return seen

    seen = run(scenario())
    signal = [int(s["Wireless Link Signal"]) for s in seen]
    quality = [int(s["Wireless Link Quality"]) for s in seen]
    assert signal[0] > signal[1] > signal[2]
    assert quality[0] > quality[1] >= quality[2]
    assert all(-100 <= v <= -20 for v in signal)
    assert seen[-1]["CPU Use"].endswith("%")


def test_wifi_walls_cost_signal():
    from rtmu.sim.wifi import AccessPoint

    open_room = AccessPoint(Obstacles(np.zeros((0, 4))), 0, 0)
    walled = AccessPoint(Obstacles(np.array([[2000, -5000, 2000, 5000], [3000, -5000, 3000, 5000]])), 0, 0)
    assert walled.link(4000, 0).walls == 2
    assert walled.link(4000, 0).signal_dbm <= open_room.link(4000, 0).signal_dbm - 9
