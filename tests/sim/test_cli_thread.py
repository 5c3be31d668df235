"""``rtmu sim`` as a process (serves; Ctrl-C stops it with SHUTDOWN) and ``SimThread`` for sync code."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

from rtmu.mapfile import read_map
from rtmu.protocol.payloads.commands import CommandList, StringCommandArgs, StringCommandList
from rtmu.protocol.payloads.popup import PopupClicked, PopupClose, PopupCreate
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim import SimConfig, SimServer, SimThread

from .wire import WireClient, run

REPO = Path(__file__).resolve().parents[2]


def test_rtmu_sim_process_serves_and_stops_cleanly_on_ctrl_c(arena_map):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--map", str(arena_map)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=REPO,
    )
    try:
        line = proc.stdout.readline()
        m = re.search(r"listening on 127\.0\.0\.1:(\d+), serving map (\S+);", line)
        assert m, line
        assert m.group(2) == str(arena_map)
        port = int(m.group(1))

        async def client() -> WireClient:
            c = await WireClient().open(port)
            numbers = UpdateNumbers.decode((await c.ask("updateNumbers"))[0])
            assert (numbers.x, numbers.y) == (0, 0)
            proc.send_signal(signal.SIGINT)
            await c.until(lambda: c.eof, timeout=10)
            await c.close(goodbye=False)
            return c

        c = run(client())
        assert c.shutdown  # told SHUTDOWN before the socket closed
        assert proc.wait(10) == 128 + signal.SIGINT  # ended by Ctrl-C, as every command
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)


def test_rtmu_sim_refuses_a_missing_map():
    out = subprocess.run(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--map", "/nonexistent.map"],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=REPO,
    )
    assert out.returncode == 2 and "no such map file" in out.stderr


def test_make_map_writes_a_generated_map(tmp_path):
    target = tmp_path / "big.map"
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "rtmu",
            "sim",
            "--make-map",
            str(target),
            "--points",
            "20000",
            "--lines",
            "800",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
    )
    assert out.returncode == 0, out.stderr
    data = read_map(target)
    assert (data.num_points, data.num_lines) == (20000, 800)
    assert data.home() is not None


def test_sim_thread_for_synchronous_code(arena_map):
    cfg = SimConfig(port=0, realtime=False, map_path=arena_map)
    with SimThread(cfg) as sim:
        assert sim.port > 0
        with socket.create_connection(("127.0.0.1", sim.port), timeout=5) as s:
            s.settimeout(5)
            assert s.recv(6)[:2] == b"\x0f\x0c"  # the server's INTRODUCTION comes at once
        sim.call(lambda: sim.server.world.ratio_drive(50, 0, 100))
        sim.advance(1.0)
        snap = sim.snapshot()
        assert snap.mode == "Drive" and 270 <= snap.vel <= 310 and snap.x > 100
        assert snap.trans_ratio == 50 and snap.throttle_ratio == 100


def test_sim_thread_kill_drops_clients_without_shutdown(arena_map):
    sim = SimThread(SimConfig(port=0, realtime=True, map_path=arena_map)).start()

    async def scenario() -> WireClient:
        c = await WireClient().open(sim.port)
        c.request("updateNumbers", 100)
        await c.wait_for("updateNumbers", 3)  # the real-time clock runs
        sim.kill()
        await c.until(lambda: c.eof)
        await c.close(goodbye=False)
        return c

    c = run(scenario())
    assert not c.shutdown


def test_commands_popups_and_low_battery(arena_map):
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=arena_map))
        await server.start()
        c = await WireClient().open(server.port)
        names = [e.name for e in CommandList.decode((await c.ask("listCommands"))[0]).commands]
        assert {"ResetTripOdometer", "SimulatorLowBattery", "safeRatioDrivingDisable"} <= set(names)
        assert all(n in c.conn.datalist for n in names)
        strings = StringCommandList.decode((await c.ask("listStringCommands"))[0]).commands
        assert [e.name for e in strings][:3] == [
            "SimulatorSetBattery",
            "SimulatorPopup",
            "SimulatorPopupFlood",
        ]
        assert {e.name for e in strings[3:]} <= {
            "mappingLoopStart",
            "mappingLoopEnd",
        }  # ARIA lists them as string commands
        c.request("popupCreate", -1)
        c.request("popupClose", -1)
        await c.barrier()
        assert c.received["popupCreate"] == []  # broadcast data: nothing until something happens
        c.once("SimulatorSetBattery", StringCommandArgs("11.505").encode())
        await c.barrier()
        await server.advance(60.0)  # the pack drains past 11.5 V: ARIA's low-battery warning
        popup = PopupCreate.decode((await c.wait_for("popupCreate"))[0])
        assert popup.popup_type == 2 and "battery" in popup.message.lower()
        listed = await c.ask("popupList")
        assert listed == [b""] and len(c.received["popupCreate"]) == 2  # re-sent, then popupList's end
        c.once("popupClicked", PopupClicked(popup.popup_id, 0).encode())
        closed = PopupClose.decode((await c.wait_for("popupClose"))[0])
        assert closed.popup_id == popup.popup_id
        await c.close()
        await server.stop()

    run(scenario())
