"""Camera pictures are shared like ARIA's video forwarder shares them: one frame per ~100 ms, for everyone."""

from __future__ import annotations

import argparse
import io
import threading

import numpy as np
import pytest
from PIL import Image

from rtmu.protocol.payloads.camera import Picture
from rtmu.sim import SimConfig, SimServer

from .wire import WireClient, run

SECONDS = 3.0


def test_a_client_asking_for_pictures_every_cycle_costs_another_clients_status_nothing(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map, drive_timeout=0))
        await server.start()
        watcher = await WireClient().open(server.port)
        hammer = await WireClient().open(server.port)
        hammer.once("SimulatorVideo640x480")
        await hammer.barrier()
        watcher.request("updateNumbers", 100)
        await watcher.wait_for("updateNumbers")
        server.world.ratio_drive(0, 60, 100)  # turning on the spot: every cycle sees something new
        hammer.request("getPictureCam1", 10)  # a picture every 10 ms cycle
        await hammer.wait_for("getPictureCam1")
        th0, renders0 = server.robot.th, server.video.renders

        await server.advance(SECONDS)

        # The status subscriber gets every packet it is due, one per 100 ms of simulated time.
        await watcher.barrier()
        assert len(watcher.received["updateNumbers"]) == 1 + round(SECONDS / 0.1)
        # The robot did turn (a new view each cycle), yet frames were rendered at most every 100 ms.
        assert abs(server.robot.th - th0) > 30
        renders = server.video.renders - renders0
        assert 0 < renders <= round(SECONDS * 10) + 1  # ARIA's forwarder: one frame per ~100 ms
        await hammer.barrier()
        pictures = hammer.received["getPictureCam1"]
        assert len(pictures) > renders  # frames were shared between the cycles' requests
        assert len({Picture.decode(p).jpeg for p in pictures}) <= renders + 1
        last = Picture.decode(pictures[-1])
        assert Image.open(io.BytesIO(last.jpeg)).size == (640, 480)
        for c in (watcher, hammer):
            await c.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_a_render_runs_off_the_cycle_and_requests_meanwhile_share_its_frame(arena_map):
    async def scenario() -> None:
        cfg = SimConfig(port=0, realtime=False, map_path=arena_map, render_in_thread=True)
        server = SimServer(cfg)
        await server.start()
        watcher, a, b = [await WireClient().open(server.port) for _ in range(3)]
        watcher.request("updateNumbers", 100)
        await watcher.wait_for("updateNumbers")
        gate = threading.Event()
        assert server.video.executor is not None
        server.video.executor.submit(gate.wait, 30.0)  # the render worker is busy until the gate opens
        try:
            a.once("getPictureCam1")
            b.once("getPictureCam1")
            a.once("getPictureCam1")
            await a.barrier()
            await b.barrier()
            assert a.received["getPictureCam1"] == b.received["getPictureCam1"] == []
            # The server cycle keeps running while the frame is still being made.
            await server.advance(1.0)
            await watcher.barrier()
            assert len(watcher.received["updateNumbers"]) == 11
            assert server.video.renders == 0
        finally:
            gate.set()
        got_a = await a.wait_for("getPictureCam1", 2)
        got_b = await b.wait_for("getPictureCam1", 1)
        assert got_a[0] == got_a[1] == got_b[0]  # one render, answered to every request that waited
        assert server.video.renders == 1
        assert Image.open(io.BytesIO(Picture.decode(got_b[0]).jpeg)).format == "JPEG"
        for c in (watcher, a, b):
            await c.close()
        await server.stop()

    run(scenario())


def test_realtime_pictures_are_rendered_on_the_worker(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=True, map_path=arena_map))
        await server.start()
        assert server.video.executor is not None
        c = await WireClient().open(server.port)
        picture = Picture.decode((await c.ask("getPictureCam1"))[0])
        assert Image.open(io.BytesIO(picture.jpeg)).size == (320, 240)
        assert server.video.renders == 1
        await c.close()
        await server.stop()

    run(scenario())


def test_frames_carry_their_render_time_and_the_camera_size_and_rate_are_settable(arena_map):
    import time

    from rtmu.client.video_feed import frame_stamp
    from rtmu.protocol.payloads.camera import VideoSize
    from rtmu.subcommands.sim import _size

    async def scenario() -> None:
        cfg = SimConfig(port=0, realtime=False, map_path=arena_map, camera_size=(640, 480), camera_hz=20.0)
        server = SimServer(cfg)
        await server.start()
        c = await WireClient().open(server.port)
        size = VideoSize.decode((await c.ask("videoSize"))[0])
        assert (size.width, size.height) == (640, 480)
        before = time.time_ns()
        first = Picture.decode((await c.ask("getPictureCam1"))[0])
        stamp = frame_stamp(first.jpeg)
        assert stamp is not None and before <= stamp <= time.time_ns()
        assert Image.open(io.BytesIO(first.jpeg)).size == (640, 480)
        server.world.ratio_drive(0, 60, 100)
        renders = server.video.renders
        await server.advance(1.0)
        again = Picture.decode((await c.ask("getPictureCam1"))[0])
        assert frame_stamp(again.jpeg) != stamp  # a new view, a new frame, a new stamp
        assert server.video.period == 0.05 and server.video.renders > renders
        await c.close()
        await server.stop()

    run(scenario(), timeout=60)
    assert _size("640x480") == (640, 480) and _size("320X240") == (320, 240)
    for bad in ("640", "0x480", "99999x2", "axb"):
        with pytest.raises(argparse.ArgumentTypeError):
            _size(bad)


def test_a_parked_robots_camera_still_delivers_fresh_frames_at_its_rate(arena_map):
    """A real camera sends new frames whatever the robot does: new noise, a new stamp, each period."""
    from rtmu.client.video_feed import frame_stamp

    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map, drive_timeout=0))
        await server.start()
        c = await WireClient().open(server.port)
        frames = []
        for _ in range(10):
            frames.append(Picture.decode((await c.ask("getPictureCam1"))[0]).jpeg)
            await server.advance(0.1)  # the robot stands still: the same view every time
        assert server.video.renders == 1, "the scene was ray-cast once"
        assert server.video.refreshes == 9, "and a fresh frame made every period after"
        assert len(set(frames)) == 10 and len({frame_stamp(f) for f in frames}) == 10
        first, last = (
            np.asarray(Image.open(io.BytesIO(f)).convert("L"), dtype=float) for f in (frames[0], frames[-1])
        )
        assert 0 < np.abs(first - last).mean() < 4, "the same scene, only the sensor's noise differs"
        await c.close()
        await server.stop()

    run(scenario())
