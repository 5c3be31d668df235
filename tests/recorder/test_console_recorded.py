"""The console's traffic is recorded like any other: its requests and the robot's replies are in the
flight recording's raw channel, because the console goes through the session's own client (the one
the recorder's tee wraps), the way the window's console page will call it.
"""

from __future__ import annotations

from pathlib import Path

from client.uiqueue import eventually
from rtmu.capture import open_capture
from rtmu.capture.conversation import DecodedPacket
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.client import console
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.protocol.fields import FieldWriter
from rtmu.recorder import Recorder, RecorderConfig
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target

from .simsession import ARENA


def test_console_requests_and_replies_are_in_the_recording(tmp_path: Path) -> None:
    out = tmp_path / "console.mcap"
    recorder = Recorder(RecorderConfig(tmp_path, path=out))
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=2)) as sim:
        runner = ClientRunner(config=SessionConfig(fetch_map=False), opener=recorder.opener())
        recorder.attach(runner)
        with runner:
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            eventually(lambda: len(recorder.recordings) == 1)
            client = runner.session.client  # type: ignore[union-attr]
            assert client is not None
            mode = console.entry_of(client.datalist.entry("getMapName"))  # type: ignore[arg-type]
            reply = runner.call(console.call, client, mode)
            name = console.entry_of(client.datalist.entry("identSetSelfIdentifier"))  # type: ignore[arg-type]
            argument = FieldWriter().string("console-probe").bytes()
            sent = runner.call(lambda: console.call(client, name, argument, confirmed=True, timeout=0.5))
        recorder.close()
    assert reply.outcome == "replied" and sent.outcome == "silent"
    replied = reply.packets[0]

    packets = [p for p in CaptureDecoder().run(open_capture(out).events()) if isinstance(p, DecodedPacket)]
    asked = [p for p in packets if p.direction == "c2s" and p.name == "getMapName"]
    answered = [p for p in packets if p.direction == "s2c" and p.name == "getMapName"]
    assert asked and answered
    assert answered[-1].payload.hex(" ") == replied.hex  # the very bytes the console showed
    probe = [p for p in packets if p.direction == "c2s" and p.name == "identSetSelfIdentifier"]
    assert [p.payload for p in probe] == [argument]
