"""``rtmu sim --central``: the switch, the forwarder shared by operators, its bounds, and the CLI.

The central server, the robots and the operators run in one event loop over real loopback sockets.
"""

from __future__ import annotations

import asyncio
import contextlib
import signal
import subprocess
import sys
import time
from collections.abc import AsyncIterator
from typing import Any

from patience import PATIENCE
from rtmu.client.call_values import Packet
from rtmu.client.central import list_robots
from rtmu.client.connection import AriaClient
from rtmu.client.errors import ClientError
from rtmu.protocol.client_connection import ClientConnection
from rtmu.protocol.events import DataListReady
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.central import CentralConfig, CentralServer
from rtmu.values.target import Target

from .wire import run

FAST = dict(port=0, camera=False, switch_retry=0.1)


async def until(predicate: Any, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout * PATIENCE
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError("condition not reached in time")
        await asyncio.sleep(0.01)


@contextlib.asynccontextmanager
async def central_with(
    *names: str, **config: Any
) -> AsyncIterator[tuple[CentralServer, dict[str, SimServer]]]:
    central = CentralServer(CentralConfig(port=0, robot_port=0, **config))
    await central.start()
    sims: dict[str, SimServer] = {}
    try:
        for name in names:
            sim = SimServer(SimConfig(switch_to=f"127.0.0.1:{central.robot_port}", switch_name=name, **FAST))
            await sim.start()
            sims[name] = sim
        await until(lambda: len(central.robots()) == len(names))
        yield central, sims
    finally:
        for sim in sims.values():
            await sim.stop()
        await central.stop()


def port_of(central: CentralServer, name: str) -> int:
    return next(e.port for e in central.robots() if e.name == name)


def central_session_subscriptions(sim: SimServer) -> set[str]:
    """What the central server (the robot's one client here) has subscribed to on the robot, for operators
    (its own 1 s ``centralHeartbeat``, which ARIA's forwarder always asks for, is left out)."""
    (session,) = sim.sessions
    return {sub.name for sub in session.subscriptions.values()} - {"centralHeartbeat"}


def test_two_operators_share_one_forwarded_robot_and_the_last_stop_stops_it() -> None:
    async def main() -> None:
        async with central_with("solo") as (central, sims):
            port = port_of(central, "solo")
            a, b, idle = AriaClient(), AriaClient(), AriaClient()
            await a.connect(Target("127.0.0.1", port), timeout=5)
            await b.connect(Target("127.0.0.1", port), timeout=5)
            await idle.connect(Target("127.0.0.1", port), timeout=5)  # asks for nothing, so hears nothing
            idle_before = idle.packets_received
            got: dict[str, int] = {"a": 0, "b": 0}

            def counter(key: str) -> Any:
                def on(packet: Packet) -> None:
                    got[key] += 1

                return on

            a.request("updateNumbers", 50, counter("a"))
            b.request("updateNumbers", 200, counter("b"))
            await until(lambda: got["a"] > 3 and got["b"] > 1)
            assert central_session_subscriptions(sims["solo"]) == {"updateNumbers"}

            a.stop_request("updateNumbers")
            await asyncio.sleep(0.1)
            before = got["b"]
            await until(lambda: got["b"] > before + 1)  # b still hears it
            assert central_session_subscriptions(sims["solo"]) == {"updateNumbers"}

            await b.disconnect()  # the last subscriber leaves: the robot is told to stop sending
            await until(lambda: central_session_subscriptions(sims["solo"]) == set())
            answered = await a.request_once("updateStrings", timeout=5)  # a still works once
            assert answered.decode()
            await a.disconnect()
            assert idle.packets_received == idle_before
            await idle.disconnect()

    run(main())


def test_an_operator_of_a_robot_that_leaves_is_told_shutdown_and_the_robot_is_unlisted() -> None:
    async def main() -> None:
        async with central_with("goner", "stayer") as (central, sims):
            closed: list[ClientError] = []
            op = AriaClient(on_close=closed.append)
            await op.connect(Target("127.0.0.1", port_of(central, "goner")), timeout=5)
            await sims.pop("goner").stop()
            await until(lambda: bool(closed))
            assert "shut" in str(closed[0]) or "closed" in str(closed[0])
            await until(lambda: [e.name for e in central.robots()] == ["stayer"])
            await op.disconnect()

    run(main())


def test_the_robot_port_speaks_arias_switch_and_a_plain_client_can_list_it() -> None:
    async def main() -> None:
        async with central_with() as (central, _):
            client = AriaClient()
            datalist = await client.connect(Target("127.0.0.1", central.robot_port), timeout=5)
            assert "switch" in datalist and "centralServerHeartbeat" in datalist
            await client.disconnect()
            ops = AriaClient()
            listed = await ops.connect(Target("127.0.0.1", central.port), timeout=5)
            assert [e.name for e in listed] == ["clientList", "clientAdded", "clientRemoved"]
            await ops.disconnect()

    run(main())


def test_a_robot_that_switches_but_never_logs_in_costs_nothing_and_is_never_listed() -> None:
    async def main() -> None:
        async with central_with("real", login_timeout=0.5) as (central, _):
            reader, writer = await asyncio.open_connection("127.0.0.1", central.robot_port)
            conn = ClientConnection()
            while True:  # log in and ask switch, then go silent instead of introducing a server
                events = conn.receive_data(await reader.read(65536))
                writer.write(conn.data_to_send())
                if any(isinstance(e, DataListReady) for e in events):
                    break
            conn.request_once("switch", b"silent\x00")
            writer.write(conn.data_to_send())
            assert await asyncio.wait_for(reader.read(65536), 5)  # the acceptance
            while await asyncio.wait_for(reader.read(65536), 5):  # given up on: a goodbye, then closed
                pass
            assert [e.name for e in central.robots()] == ["real"]
            assert [f.name for f in central.forwarders] == ["real"]
            writer.close()

    run(main())


def test_robots_beyond_the_bound_are_closed_at_once() -> None:
    async def main() -> None:
        async with central_with("one", "two", max_robots=2) as (central, _):
            reader, writer = await asyncio.open_connection("127.0.0.1", central.robot_port)
            assert await asyncio.wait_for(reader.read(65536), 5) == b""
            writer.close()
            assert len(central.forwarders) == 2

    run(main())


def test_garbage_on_the_robot_port_is_dropped_without_a_switch() -> None:
    async def main() -> None:
        async with central_with("one", login_timeout=0.5) as (central, _):
            reader, writer = await asyncio.open_connection("127.0.0.1", central.robot_port)
            writer.write(b"\x0f\x0c\xff\xff" + bytes(range(256)) * 64)
            with contextlib.suppress(ConnectionError):
                while await asyncio.wait_for(reader.read(65536), 5):
                    pass
            writer.close()
            assert central.switches == 1 and [e.name for e in central.robots()] == ["one"]

    run(main())


def test_a_robot_switches_again_when_the_central_server_comes_back() -> None:
    async def main() -> None:
        central = CentralServer(CentralConfig(port=0, robot_port=0))
        await central.start()
        robot_port = central.robot_port
        sim = SimServer(SimConfig(switch_to=f"127.0.0.1:{robot_port}", switch_name="back", **FAST))
        await sim.start()
        try:
            await until(lambda: len(central.robots()) == 1)
            central.kill()
            again = CentralServer(CentralConfig(port=0, robot_port=robot_port))
            await again.start()
            await until(lambda: [e.name for e in again.robots()] == ["back"])
            robots = await list_robots("127.0.0.1", again.port, timeout=5)
            assert [e.name for e, _ in robots] == ["back"]
            await again.stop()
        finally:
            await sim.stop()
            await central.stop()

    run(main())


def test_rtmu_sim_central_with_robots_serves_a_fleet_and_stops_on_sigint() -> None:
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rtmu",
            "sim",
            "--central",
            "--port",
            "0",
            "--robot-port",
            "0",
            "--robots",
            "2",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()
        assert first.startswith("rtmu sim: ARIA central server: operators on 127.0.0.1:")
        port = int(first.split("operators on 127.0.0.1:")[1].split(",")[0])
        assert proc.stdout.readline().startswith("rtmu sim: 2 simulated robots")

        async def names() -> list[str]:
            deadline = time.monotonic() + 20
            while True:
                robots = await list_robots("127.0.0.1", port, timeout=5)
                if len(robots) == 2 or time.monotonic() > deadline:
                    return [e.name for e, _ in robots]
                await asyncio.sleep(0.1)

        assert run(names()) == ["robot1", "robot2"]

        async def poses() -> set[tuple[int, int]]:
            seen = set()
            for endpoint, _ in await list_robots("127.0.0.1", port, timeout=5):
                client = AriaClient()
                await client.connect(Target(endpoint.host, endpoint.port), timeout=5)
                try:
                    numbers = UpdateNumbers.decode((await client.request_once("updateNumbers")).payload)
                    seen.add((numbers.x, numbers.y))
                finally:
                    await client.disconnect()
            return seen

        assert len(run(poses())) == 2, "two robots start at the same place"
        proc.send_signal(signal.SIGINT)
        assert proc.wait(15) == 128 + signal.SIGINT  # ended by Ctrl-C, as every command
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_rtmu_sim_refuses_too_many_central_robots_and_a_bad_switch_address() -> None:
    """``--robots`` alone means N direct robots (``sim.multi``); behind ``--central`` it is bounded too."""
    for argv, words in (
        (["--central", "--robots", "101"], "with --central, --robots takes 0…100"),
        (["--switch-to", "host:99999"], "bad central server address"),
    ):
        done = subprocess.run(
            [sys.executable, "-m", "rtmu", "sim", "--port", "0", *argv],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert done.returncode == 2 and words in done.stderr


def test_request_onces_from_two_operators_each_get_their_own_reply() -> None:
    async def main() -> None:
        async with central_with("shared") as (central, _):
            port = port_of(central, "shared")
            ops = [AriaClient() for _ in range(3)]
            for op in ops:
                await op.connect(Target("127.0.0.1", port), timeout=5)
            for _ in range(5):  # all at once: the forwarder's queue hands each reply to its asker
                replies = await asyncio.gather(
                    *(
                        op.request_once(name, timeout=5)
                        for op in ops
                        for name in ("updateStrings", "getMapName")
                    )
                )
                assert len(replies) == 6 and all(r.payloads for r in replies)
            for op in ops:
                await op.disconnect()

    run(main())


def test_arias_forwarding_rules_by_return_type() -> None:
    from rtmu.protocol.datalist import DataEntry
    from rtmu.sim.forwarder import Return, return_type

    def kind(flags: str) -> Return | None:
        return return_type(DataEntry(300, "x", flags=flags))

    assert kind("RETURN_SINGLE") is Return.SINGLE
    assert kind("RETURN_UNTIL_EMPTY") is Return.UNTIL_EMPTY
    assert kind("RETURN_VIDEO") is Return.VIDEO
    assert kind("RETURN_NONE|SLOW") is Return.NONE
    assert kind("RETURN_COMPLEX") is None and kind("") is None
    assert kind("RETURN_SINGLE|DO_NOT_FORWARD") is None


def test_a_user_file_guards_the_central_port_and_every_forwarder(tmp_path) -> None:  # type: ignore[no-untyped-def]
    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\n")

    async def main() -> None:
        async with central_with("guarded", users_path=users) as (central, _):
            for port in (central.port, port_of(central, "guarded")):
                stranger = AriaClient()
                try:
                    await stranger.connect(Target("127.0.0.1", port, "mallory", "guess"), timeout=5)
                    raise AssertionError("a wrong password was let in")
                except ClientError as exc:
                    assert "password" in str(exc).lower() or "refused" in str(exc).lower()
                alice = AriaClient()
                await alice.connect(Target("127.0.0.1", port, "alice", "secret1"), timeout=5)
                await alice.disconnect()
            robots = await list_robots("127.0.0.1", central.port, "alice", "secret1", timeout=5)
            assert [e.name for e, _ in robots] == ["guarded"]

    run(main())


async def _mute_robot(robot_port: int, name: str) -> asyncio.StreamWriter:
    """A robot that switches, lets the central server log in, then never sends another byte (its link
    died without a reset): it answers none of the forwarder's heartbeats."""
    from rtmu.protocol.datalist import DataList
    from rtmu.protocol.server_connection import ServerConnection

    reader, writer = await asyncio.open_connection("127.0.0.1", robot_port)
    conn = ClientConnection()
    while True:
        events = conn.receive_data(await reader.read(65536))
        writer.write(conn.data_to_send())
        if any(isinstance(e, DataListReady) for e in events):
            break
    conn.request_once("switch", name.encode() + b"\x00")
    writer.write(conn.data_to_send())
    await reader.read(65536)  # the acceptance
    served = ServerConnection(
        DataList.build([("centralHeartbeat", "", "none", "none", "RobotInfo", "RETURN_SINGLE")])
    )
    writer.write(served.data_to_send())
    while served.state.name != "CONNECTED":
        served.receive_data(await reader.read(65536))
        writer.write(served.data_to_send())
    return writer


def test_a_robot_gone_silent_is_dropped_and_unlisted() -> None:
    async def main() -> None:
        async with central_with("talker", robot_silence_s=1.5) as (central, _):
            writer = await _mute_robot(central.robot_port, "mute")
            await until(lambda: sorted(e.name for e in central.robots()) == ["mute", "talker"])
            await until(lambda: [e.name for e in central.robots()] == ["talker"], timeout=10)
            await asyncio.sleep(2.0)  # the talker answers its heartbeats: never dropped, never switched again
            assert [e.name for e in central.robots()] == ["talker"] and central.switches == 2
            writer.close()

    run(main())


def test_an_operator_flooding_requests_cannot_cost_the_robot_or_the_other_operators() -> None:
    from rtmu.protocol.packet import encode_packet

    async def main() -> None:
        async with central_with("busy") as (central, sims):
            port = port_of(central, "busy")
            calm = AriaClient()
            await calm.connect(Target("127.0.0.1", port), timeout=5)
            flooder = AriaClient()
            await flooder.connect(Target("127.0.0.1", port), timeout=5)
            number = flooder.datalist.number("getMapName")
            assert number is not None
            _, writer = await asyncio.open_connection("127.0.0.1", port)  # and a raw one, never logging in
            burst = encode_packet(number, b"") * 10_000
            for _ in range(5):  # 80 kB of request-onces from each, far faster than the replies can be read
                flooder._link.write(burst)  # type: ignore[union-attr]
                writer.write(burst)
                await asyncio.sleep(0)
            for _ in range(3):
                assert (await calm.request_once("updateNumbers", timeout=10)).payloads
            assert [e.name for e in central.robots()] == ["busy"]
            writer.close()
            await flooder.disconnect()
            await calm.disconnect()
            assert sims["busy"].sessions  # the robot's switched connection is still up

    run(main())


def test_a_client_list_larger_than_a_packet_is_cut_to_what_one_packet_holds() -> None:
    async def main() -> None:
        async with central_with() as (central, _):
            names = [f"r{i:03d}" + "x" * 500 for i in range(70)]  # 70 × ~510 bytes > one packet
            writers = [await _mute_robot(central.robot_port, name) for name in names]
            await until(lambda: len(central.robots()) == 70)
            robots = await list_robots("127.0.0.1", central.port, timeout=5)
            assert 55 < len(robots) < 70
            assert [e.name for e, _ in robots] == names[: len(robots)]
            for writer in writers:
                writer.close()

    run(main())


def test_connections_that_never_switch_count_against_the_robot_bound() -> None:
    async def main() -> None:
        async with central_with(max_robots=2, login_timeout=1.0) as (central, _):
            idle = [await asyncio.open_connection("127.0.0.1", central.robot_port) for _ in range(2)]
            await asyncio.sleep(0.1)
            reader, writer = await asyncio.open_connection("127.0.0.1", central.robot_port)
            assert await asyncio.wait_for(reader.read(65536), 5) == b""  # closed at once: no slot
            writer.close()
            for r, w in idle:  # the idle ones are dropped after the login timeout, freeing the slots
                with contextlib.suppress(ConnectionError):
                    while await asyncio.wait_for(r.read(65536), 5):
                        pass
                w.close()
            writer = await _mute_robot(central.robot_port, "late")
            await until(lambda: [e.name for e in central.robots()] == ["late"])
            writer.close()

    run(main())


def test_a_robot_that_switches_then_sends_a_malformed_introduction_is_not_forwarded() -> None:
    from rtmu.protocol.commands import ServerCommand
    from rtmu.protocol.packet import encode_packet

    async def main() -> None:
        async with central_with("good") as (central, _):
            reader, writer = await asyncio.open_connection("127.0.0.1", central.robot_port)
            conn = ClientConnection()
            while True:
                events = conn.receive_data(await reader.read(65536))
                writer.write(conn.data_to_send())
                if any(isinstance(e, DataListReady) for e in events):
                    break
            conn.request_once("switch", b"liar\x00")
            writer.write(conn.data_to_send())
            await reader.read(65536)  # the acceptance
            writer.write(encode_packet(ServerCommand.INTRODUCTION, b"\xff"))  # an introduction cut short
            with contextlib.suppress(ConnectionError):
                while await asyncio.wait_for(reader.read(65536), 5):
                    pass
            assert [e.name for e in central.robots()] == ["good"] and len(central.forwarders) == 1
            writer.close()

    run(main())


def test_a_robot_drops_a_central_server_whose_heartbeats_stop_and_switches_again() -> None:
    async def main() -> None:
        # This central server promises heartbeats (it lists centralServerHeartbeat) but sends one an hour.
        async with central_with(heartbeat_s=3600) as (central, _):
            sim = SimServer(
                SimConfig(
                    switch_to=f"127.0.0.1:{central.robot_port}",
                    switch_name="wary",
                    switch_silence=0.5,
                    **FAST,
                )
            )
            await sim.start()
            try:
                await until(lambda: central.switches >= 2, timeout=10)  # dropped, then switched again
                assert sim.central_heartbeats is not None and sim.central_heartbeats.count <= central.switches
            finally:
                await sim.stop()

        async with central_with() as (central, _):  # heartbeats every second: the link is kept
            sim = SimServer(
                SimConfig(
                    switch_to=f"127.0.0.1:{central.robot_port}",
                    switch_name="calm",
                    switch_silence=1.5,
                    **FAST,
                )
            )
            await sim.start()
            try:
                await until(lambda: len(central.robots()) == 1)
                await asyncio.sleep(3.0)
                assert central.switches == 1
                assert sim.central_heartbeats is not None and sim.central_heartbeats.count >= 2
            finally:
                await sim.stop()

    run(main())
