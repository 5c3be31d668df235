"""Omron LD robots (ARAM) on the wire, against ``rtmu sim --kind aram`` and the default profile.

The protocol string (answered as advertised, ``--protocol`` overrides, reason 4 names the wanted
string), the battery as state of charge, and ``rtmu doctor`` step by step — all over loopback.
"""

from __future__ import annotations

import asyncio
import json
import socket
from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK
from rtmu.cli import main
from rtmu.client.connection import AriaClient
from rtmu.client.diagnosis import Step, explain
from rtmu.client.errors import LoginRejected
from rtmu.package_data import project_map
from rtmu.protocol.payloads.robot import BatteryInfo
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.profiles import ARAM, ARAM_PROTOCOL
from rtmu.values.target import Target
from simulators import simulator

OFFICE = project_map("office.map")
ARAM_COUNT = len(ARAM.catalogue(camera=True))
"""The aram profile lists only what 6MTX robots list (and what the simulator serves of it)."""


aram = simulator(scope="module", profile="aram", map_path=OFFICE)


plain = simulator(scope="module", users=("alice secret1 all",))


def addr(sim: SimThread) -> str:
    return f"127.0.0.1:{sim.port}"


async def _login(port: int, protocol: str | None) -> AriaClient:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port, protocol=protocol), timeout=5.0)
    return client


def test_default_answer_is_the_advertised_string(aram: SimThread) -> None:
    async def go() -> int:
        client = await _login(aram.port, None)
        try:
            return len(list(client.datalist))
        finally:
            await client.disconnect()

    assert asyncio.run(go()) == ARAM_COUNT


def test_wrong_protocol_names_the_wanted_string(aram: SimThread) -> None:
    with pytest.raises(LoginRejected) as info:
        asyncio.run(_login(aram.port, "wrong"))
    assert info.value.reason == 4
    assert info.value.wanted_protocol == ARAM_PROTOCOL
    assert "'6MTX'" in str(info.value) and "'wrong'" in str(info.value)
    finding = explain(info.value)
    assert finding.step is Step.LOGIN and "--protocol 6MTX" in finding.sentence()


def test_cli_wrong_protocol_exits_3_with_the_wanted_string(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["probe", addr(aram), "--protocol", "wrong", "--timeout", cli_timeout(5)])
    err = capsys.readouterr().err
    assert code == EXIT_CONNECTION
    assert "wants protocol '6MTX'; we sent 'wrong'" in err and "--protocol 6MTX" in err


def test_cli_explicit_right_protocol_logs_in(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["probe", addr(aram), "--protocol", "6MTX", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["count"] == ARAM_COUNT


def test_sim_protocol_option_enforces_and_advertises() -> None:
    with SimThread(SimConfig(port=0, protocol_version="D6MTX")) as sim:
        raw = socket.create_connection(("127.0.0.1", sim.port), timeout=5)
        try:
            raw.settimeout(5)
            intro = raw.recv(4096)
        finally:
            raw.close()
        assert b"D6MTX\x00" in intro  # field 6 of the server INTRODUCTION
        with pytest.raises(LoginRejected):
            asyncio.run(_login(sim.port, ""))


def test_status_json_has_battery_pct_on_aram(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["status", addr(aram), "--once", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    assert "battery_v" not in obj
    assert 0.0 <= obj["battery_pct"] <= 100.0
    assert obj["battery_pct"] == pytest.approx(100.0, abs=0.5)  # a full simulated battery


def test_status_json_has_battery_v_on_default(plain: SimThread, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pw = tmp_path / "pw"
    pw.write_text("secret1\n")
    args = ["status", addr(plain), "--once", "--json", "--user", "alice", "--password-file", str(pw)]
    assert main(args) == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    assert "battery_pct" not in obj and obj["battery_v"] == pytest.approx(12.8, abs=0.05)


def test_status_text_line_says_percent(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["status", addr(aram), "--once", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert "battery=100 %" in capsys.readouterr().out


def test_battery_info_without_the_flag_means_volts() -> None:
    full = BatteryInfo(11.5, 11.0, True).encode()
    assert BatteryInfo.decode(full).state_of_charge is True
    assert BatteryInfo.decode(full[:-1]) == BatteryInfo(11.5, 11.0, False)


# -- rtmu doctor ---------------------------------------------------------------------------------------
def doctor_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict]:
    code = main(["doctor", *args, "--json", "--timeout", cli_timeout(5)])
    return code, json.loads(capsys.readouterr().out)


def test_doctor_good_aram_sim(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code, report = doctor_json(capsys, addr(aram))
    assert code == EXIT_OK and report["ok"] is True and report["failed_step"] is None
    steps = {s["step"]: s for s in report["steps"]}
    assert list(steps) == ["resolve", "tcp", "introduction", "login", "data_list", "udp", "status", "motion"]
    assert steps["introduction"]["protocol"] == "6MTX" and steps["introduction"]["sent_protocol"] == "6MTX"
    assert steps["data_list"]["count"] == ARAM_COUNT
    assert "its configuration is Omron LD's" in steps["data_list"]["summary"]
    assert report["features"]["configuration"] is False  # getConfigValues is not ArConfig
    assert report["features"]["teleop"] is True
    assert steps["udp"]["result"] == "not_checked"  # the simulator announces UDP port 0
    assert 0 <= steps["status"]["battery_pct"] <= 100
    for s in report["steps"]:
        assert set(s) >= {"step", "title", "result", "summary", "advice"}


def test_doctor_closed_port(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # bound, never listening: connecting is refused
        code, report = doctor_json(capsys, f"127.0.0.1:{port}")
    assert code == Step.TCP.value == 11
    assert report["failed_step"] == "tcp"
    tcp = next(s for s in report["steps"] if s["step"] == "tcp")
    assert "refused" in tcp["summary"] and "7272" in tcp["advice"]
    assert all(s["result"] == "skipped" for s in report["steps"][2:])


def test_doctor_wrong_password(plain: SimThread, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pw = tmp_path / "pw"
    pw.write_text("not-it\n")
    code, report = doctor_json(capsys, addr(plain), "--user", "alice", "--password-file", str(pw))
    assert code == Step.LOGIN.value == 13
    login = next(s for s in report["steps"] if s["step"] == "login")
    assert login["result"] == "fail" and "wrong user name or password" in login["summary"]
    assert login["reason"] == 1


def test_doctor_right_password_default_profile(plain: SimThread, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pw = tmp_path / "pw"
    pw.write_text("secret1\n")
    code, report = doctor_json(capsys, addr(plain), "--user", "alice", "--password-file", str(pw))
    assert code == EXIT_OK
    status = next(s for s in report["steps"] if s["step"] == "status")
    assert "battery_v" in status and "battery_pct" not in status


def test_doctor_enforcing_sim_wrong_protocol(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code, report = doctor_json(capsys, addr(aram), "--protocol", "5MTX")
    assert code == 13 and report["failed_step"] == "login"
    login = next(s for s in report["steps"] if s["step"] == "login")
    assert "'6MTX'" in login["summary"] and "'5MTX'" in login["summary"]
    assert "--protocol 6MTX" in login["advice"]


def test_doctor_text_output(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor", addr(aram), "--protocol", "x", "--timeout", cli_timeout(5)]) == 13
    out = capsys.readouterr().out
    assert "[FAIL] login: the server wants protocol '6MTX'" in out
    assert "what to do: use --protocol 6MTX" in out
    assert "Stopped at the login step (exit 13)." in out


# -- doctor against hand-made servers: not ArNetworking, and a server with UDP ---------------------------
def test_doctor_names_a_server_that_is_not_arnetworking(capsys: pytest.CaptureFixture[str]) -> None:
    import threading

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    port = listener.getsockname()[1]

    def serve() -> None:
        conn, _ = listener.accept()
        with conn:
            conn.sendall(b"SSH-2.0-OpenSSH_9.2\r\n")
            conn.recv(1024)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        code, report = doctor_json(capsys, f"127.0.0.1:{port}")
    finally:
        listener.close()
        thread.join(5)
    assert code == Step.INTRODUCTION.value == 12
    intro = next(s for s in report["steps"] if s["step"] == "introduction")
    assert "SSH-2.0" in intro["summary"] and "not an ARIA robot server" in intro["advice"]


@pytest.mark.parametrize("answers", [True, False])
def test_doctor_udp_handshake(answers: bool) -> None:
    """A server that announces a UDP port: the doctor's UDP_INTRODUCTION gets the intro key back, or not."""
    from rtmu.protocol.datalist import DataList
    from rtmu.protocol.decoder import PacketDecoder
    from rtmu.protocol.events import RequestOnce
    from rtmu.protocol.fields import FieldReader, FieldWriter
    from rtmu.protocol.packet import encode_packet
    from rtmu.protocol.payloads.robot import UpdateNumbers
    from rtmu.protocol.server_connection import ServerConnection
    from rtmu.subcommands.doctor import Doctor

    rows = [
        ("updateNumbers", "status", "none", "numbers", "RobotInfo", "RETURN_SINGLE"),
        ("ratioDrive", "drive", "doubles", "none", "Movement", "RETURN_NONE"),
        ("stop", "stop", "none", "none", "Stop", "RETURN_NONE"),  # else the motion step warns: no stop
    ]
    conns: list[ServerConnection] = []

    class UdpSide(asyncio.DatagramProtocol):
        def connection_made(self, transport) -> None:  # type: ignore[no-untyped-def]
            self.transport = transport

        def datagram_received(self, data: bytes, addr) -> None:  # type: ignore[no-untyped-def]
            for packet in PacketDecoder().feed(data):
                key = FieldReader(packet.payload).ubyte4("auth key", default=-1)
                for conn in conns:
                    if packet.command == 3 and key == conn.auth_key and answers:
                        reply = encode_packet(3, FieldWriter().byte4(conn.intro_key).bytes())
                        self.transport.sendto(reply, addr)

    async def go() -> Doctor:
        loop = asyncio.get_running_loop()
        udp, _ = await loop.create_datagram_endpoint(UdpSide, local_addr=("127.0.0.1", 0))
        udp_port = udp.get_extra_info("sockname")[1]

        async def on_client(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
            conn = ServerConnection(DataList.build(rows), udp_port=udp_port)
            conns.append(conn)
            writer.write(conn.data_to_send())
            while data := await reader.read(65536):
                for event in conn.receive_data(data):
                    if isinstance(event, RequestOnce) and event.name == "updateNumbers":
                        conn.send_data("updateNumbers", UpdateNumbers(87.0, 1, 2, 3, 0, 0, 0, 20).encode())
                writer.write(conn.data_to_send())
            writer.close()

        server = await asyncio.start_server(on_client, "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        try:
            doctor = Doctor("127.0.0.1", port, "", "", None, 5.0)
            assert await doctor.run() == EXIT_OK
            return doctor
        finally:
            server.close()
            udp.close()

    doctor = asyncio.run(go())
    udp_step = next(s for s in doctor.steps if s.step is Step.UDP)
    if answers:
        assert udp_step.result == "ok" and "answers" in udp_step.summary
    else:
        assert udp_step.result == "warn" and "does not stop RTMU" in udp_step.advice
    status = next(s for s in doctor.steps if s.step is Step.STATUS)
    assert status.details["battery_v"] == 87.0  # no batteryInfo listed: the figure is volts
