"""``rtmu video``: live video from the simulator and from a hostile camera, over real loopback sockets."""

from __future__ import annotations

import io
import itertools
import json
from collections.abc import Iterator

import pytest
from PIL import Image

from client.servers import ServerSide, ServerThread, TestServer
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from simulators import running

ARENA = project_map("arena.map")
SUMMARY_KEYS = {"frames", "fps", "kbps", "width", "height", "age_ms_p50", "age_ms_p95"}


@pytest.fixture(scope="module")
def turning_sim() -> Iterator[SimThread]:
    """A 640x480 camera serving up to 20 new frames/s on a robot turning on the spot (every frame new)."""
    with running(map_path=ARENA, camera_size=(640, 480), camera_hz=20.0, drive_timeout=0) as sim:
        assert sim.server is not None
        world = sim.server.world
        sim.call(lambda: world.ratio_drive(0, 40, 100))
        yield sim


def test_video_json_reports_live_640x480_frames_with_their_age(turning_sim, tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "frames"
    code = main(
        [
            "video",
            f"127.0.0.1:{turning_sim.port}",
            "--seconds",
            "3",
            "--json",
            "--out",
            str(out),
            "--fps",
            "20",
        ]
    )
    captured = capsys.readouterr()
    assert code == EXIT_OK, captured.err
    summary = json.loads(captured.out)
    assert summary.keys() >= SUMMARY_KEYS
    assert (summary["width"], summary["height"]) == (640, 480)
    # A turning robot gives a new picture each frame; even a loaded machine manages a few per second.
    assert summary["frames"] >= 6
    assert summary["fps"] > 2 and summary["kbps"] > 0
    # The simulator stamps each frame's render time, so the age is measured end to end.
    assert summary["age_ms_p50"] is not None and 0 <= summary["age_ms_p50"] <= summary["age_ms_p95"]
    saved = sorted(out.glob("frame_*.jpg"))
    assert len(saved) == summary["frames"]
    pictures = {p.read_bytes() for p in saved}
    assert len(pictures) == len(saved)  # every saved frame is a different picture
    with Image.open(saved[-1]) as img:
        assert img.size == (640, 480)


def test_video_fps_setting_caps_the_request_rate(turning_sim, capsys) -> None:  # type: ignore[no-untyped-def]
    code = main(["video", f"127.0.0.1:{turning_sim.port}", "--seconds", "3", "--json", "--fps", "2"])
    captured = capsys.readouterr()
    assert code == EXIT_OK, captured.err
    summary = json.loads(captured.out)
    assert 1 <= summary["frames"] <= 8  # 2 per second for 3 s, plus the first, whatever the load
    assert summary["target_fps"] == 2


def jpeg(width: int, height: int, colour: tuple[int, int, int]) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", (width, height), colour).save(out, "JPEG")
    return out.getvalue()


def huge_dimensions(data: bytes) -> bytes:
    """A real JPEG whose frame header claims 60000x60000 pixels."""
    at = data.index(b"\xff\xc0")
    return data[: at + 5] + (60000).to_bytes(2, "big") + (60000).to_bytes(2, "big") + data[at + 9 :]


def hostile_camera() -> TestServer:
    """A camera whose frames cycle through good ones and every kind of bad one, forever."""
    good = [jpeg(64, 48, (10 * i, 90, 160)) for i in range(4)]
    frames = [
        (64, 48, good[0]),
        (64, 48, b"\x89PNG\r\n not a jpeg at all" * 10),
        (64, 48, good[1]),
        (64, 48, good[2][: len(good[2]) // 2]),  # cut short
        (64, 48, huge_dimensions(good[3])),
        (40000, 40000, good[3]),  # a size field that claims too much
        (64, 48, good[3]),
    ]
    cycle = itertools.cycle(frames)
    server = TestServer()

    def answer(side: ServerSide, args: bytes) -> None:
        w, h, data = next(cycle)
        side.conn.send_data("getPictureCam1", w.to_bytes(2, "little") + h.to_bytes(2, "little") + data)
        side.writer.write(side.conn.data_to_send())

    server.handlers["getPictureCam1"] = answer
    return server


def test_bad_frames_are_dropped_with_a_note_and_the_video_goes_on(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "frames"
    with ServerThread(hostile_camera()) as running:
        code = main(
            [
                "video",
                f"127.0.0.1:{running.port}",
                "--seconds",
                "2",
                "--json",
                "--fps",
                "20",
                "--out",
                str(out),
            ]
        )
    captured = capsys.readouterr()
    assert code == EXIT_OK, captured.err
    summary = json.loads(captured.out)
    assert summary["frames"] >= 4  # good frames after bad ones kept coming
    assert summary["dropped"] >= 4
    err = captured.err
    assert "not a JPEG picture" in err
    assert "cut short" in err
    assert "60000x60000" in err
    assert "40000x40000" in err
    assert len(list(out.glob("*.jpg"))) == summary["frames"]
    for saved in out.glob("*.jpg"):
        with Image.open(saved) as img:
            assert img.size == (64, 48)


def test_a_camera_with_only_bad_frames_exits_3_with_the_reason(capsys) -> None:  # type: ignore[no-untyped-def]
    server = TestServer()

    def answer(side: ServerSide, args: bytes) -> None:
        side.conn.send_data(
            "getPictureCam1", (64).to_bytes(2, "little") + (48).to_bytes(2, "little") + b"junk"
        )
        side.writer.write(side.conn.data_to_send())

    server.handlers["getPictureCam1"] = answer
    with ServerThread(server) as running:
        code = main(["video", f"127.0.0.1:{running.port}", "--seconds", "1", "--json"])
    assert code == EXIT_CONNECTION
    assert "no frame could be shown" in capsys.readouterr().err


def test_a_parked_robots_camera_plays_as_video_and_repeats_are_told_apart(capsys) -> None:  # type: ignore[no-untyped-def]
    """Standing still, the simulated camera still sends fresh frames (it sent one in minutes before);
    a repeated frame — the camera had nothing newer — is named as such, not taken for a slow link."""
    with SimThread(SimConfig(port=0, map_path=ARENA, camera_hz=10.0)) as sim:
        where = f"127.0.0.1:{sim.port}"
        assert (
            main(["video", where, "--seconds", "2", "--fps", "10", "--json", "--timeout", cli_timeout(5)])
            == EXIT_OK
        )
        summary = json.loads(capsys.readouterr().out)
        assert summary["frames"] >= 4, summary  # a camera that renews its picture: not one frame in 2 s
        assert summary["backoff"] == "", "fresh frames are young: nothing to slow down for"
        assert main(["video", where, "--seconds", "1", "--fps", "30", "--timeout", cli_timeout(5)]) == EXIT_OK
        line = capsys.readouterr().out
        assert "repeats (the camera had no newer picture" in line, line  # asked 30/s of a 10/s camera
