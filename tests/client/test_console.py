"""The console (``rtmu call`` and its model) against the simulator and against hostile servers, on loopback.

What is checked: the whole data list with its texts, a read and a subscription, arguments typed
from the description, a call that changes something refused without confirmation (nothing sent),
``ratioDrive`` and subscriptions of commands always refused, silence reported as such, and
hostile replies — a count that lies, a hundred thousand fields, an endless stream, a header that
promises bytes that never come — answered in bounded time with bounded views.
"""

from __future__ import annotations

import json
import threading

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_TIMEOUT, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.connection import AriaClient
from rtmu.client.console import (
    ConsoleRefusal,
    NeedsConfirmation,
    Subscription,
    call,
    console_entries,
    entry_of,
)
from rtmu.client.console_reply import MAX_FIELDS_SHOWN
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.packet import encode_packet
from rtmu.sim import SimThread
from rtmu.values.target import Target
from simulators import simulator

from .servers import SPECS, ServerSide, ServerThread, TestServer, run

sim = simulator(scope="module", seed=3)


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


async def connected(port: int) -> AriaClient:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port), timeout=10)
    return client


# -- the simulator ----------------------------------------------------------------------------------
def test_list_shows_every_data_with_its_texts_and_effect(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["call", addr(sim.port), "--list", "--json", "--timeout", cli_timeout(10)]) == EXIT_OK
    listed = {e["name"]: e for e in json.loads(capsys.readouterr().out)}
    served = sim.server.datalist  # type: ignore[union-attr]
    assert set(listed) == {e.name for e in served}
    goto = listed["gotoPose"]
    entry = served.entry("gotoPose")
    assert entry is not None
    assert (goto["description"], goto["arguments"], goto["returns"], goto["group"], goto["flags"]) == (
        entry.description,
        entry.argument_description,
        entry.return_description,
        entry.command_group,
        entry.flags,
    )
    assert goto["effect"] == "changes something" and listed["getGoals"]["effect"] == "read"
    assert main(["call", addr(sim.port), "--list", "battery", "--timeout", cli_timeout(10)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "batteryInfo" in out and "gotoPose" not in out


def test_a_read_prints_bytes_fields_and_the_known_type(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["call", addr(sim.port), "getModeInfo", "--timeout", cli_timeout(10)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "getModeInfo: replied: 1 packet" in out
    assert 'string "stop"  (mode)' in out
    assert "as ModeInfo:" in out and '"mode_name":"stop"' in out
    assert main(["call", addr(sim.port), "getMapName", "--json", "--timeout", cli_timeout(10)]) == EXIT_OK
    reply = json.loads(capsys.readouterr().out)
    assert reply["outcome"] == "replied" and reply["packets"][0]["fields"][0]["kind"] == "string"


def test_a_subscription_prints_a_reply_per_interval(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["call", addr(sim.port), "updateNumbers", "--every", "100", "--seconds", "1.5", "--json"])
    assert code == EXIT_OK
    replies = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(replies) >= 3  # 100 ms asked for 1.5 s: at least a few, however loaded the machine
    assert all(r["packets"][0]["typed"]["type"] == "UpdateNumbers" for r in replies)
    assert sim.call(lambda: len(sim.server.sessions)) is not None  # type: ignore[union-attr]


def test_a_change_needs_yes_and_nothing_is_sent_without_it(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    before = sim.call(lambda: sim.server.world.body.battery_v)  # type: ignore[union-attr]
    code = main(["call", addr(sim.port), "SimulatorSetBattery", "11.75", "--timeout", cli_timeout(10)])
    assert code == EXIT_USAGE
    err = capsys.readouterr().err
    assert "changes something" in err and "--yes" in err
    assert sim.call(lambda: sim.server.world.body.battery_v) == pytest.approx(before, abs=0.05)  # type: ignore[union-attr]
    code = main(
        ["call", addr(sim.port), "SimulatorSetBattery", "11.75", "--yes", "--timeout", cli_timeout(10)]
    )
    assert code == EXIT_OK
    assert "taken" in capsys.readouterr().out
    assert sim.call(lambda: sim.server.world.body.battery_v) == pytest.approx(11.75)  # type: ignore[union-attr]


def test_arguments_are_typed_from_the_description(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["call", addr(sim.port), "gotoPose", "1000", "-500", "--yes", "--timeout", cli_timeout(10)])
    assert code == EXIT_OK
    assert main(["call", addr(sim.port), "stop", "--yes", "--timeout", cli_timeout(10)]) == EXIT_OK
    capsys.readouterr()
    assert (
        main(["call", addr(sim.port), "gotoPose", "1000", "--yes", "--timeout", cli_timeout(10)])
        == EXIT_USAGE
    )
    assert "takes 2 arguments" in capsys.readouterr().err
    assert (
        main(["call", addr(sim.port), "gotoPose", "x", "1", "--yes", "--timeout", cli_timeout(10)])
        == EXIT_USAGE
    )
    assert "not a whole number" in capsys.readouterr().err


def test_name_and_arguments_may_follow_options(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    """Found against ARIA's own server: ``HOST --user U --password-file F NAME`` must call NAME."""
    assert main(["call", addr(sim.port), "--timeout", cli_timeout(10), "getMapName"]) == EXIT_OK
    assert "getMapName: replied" in capsys.readouterr().out
    code = main(["call", addr(sim.port), "--timeout", cli_timeout(10), "gotoPose", "1500", "--yes", "-700"])
    assert code == EXIT_OK
    assert main(["call", addr(sim.port), "stop", "--yes", "--timeout", cli_timeout(10)]) == EXIT_OK
    with pytest.raises(SystemExit) as info:
        main(["call", addr(sim.port), "getMapName", "--bogus", "x"])
    assert info.value.code == EXIT_USAGE
    assert "unrecognized arguments: --bogus (values not shown)" in capsys.readouterr().err


def test_refusals_and_unknown_names(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["call", addr(sim.port), "ratioDrive", "50", "0", "100", "--yes"]) == EXIT_USAGE
    assert "held drive" in capsys.readouterr().err
    assert main(["call", addr(sim.port), "stop", "--every", "100", "--seconds", "1"]) == EXIT_USAGE
    assert "only sends it once" in capsys.readouterr().err
    assert main(["call", addr(sim.port), "getGoal", "--timeout", cli_timeout(10)]) == EXIT_USAGE
    assert "did you mean getGoals" in capsys.readouterr().err
    assert main(["call", addr(sim.port)]) == EXIT_USAGE
    assert sim.call(lambda: sim.server.world.body.vel) == 0  # type: ignore[union-attr]


def test_a_data_that_never_answers_is_silent(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    # popupCreate is the server's news only: asked for, nothing comes.
    code = main(["call", addr(sim.port), "popupCreate", "--yes", "--timeout", "0.5"])
    assert code == EXIT_TIMEOUT
    assert "no reply within 0.5 s" in capsys.readouterr().err


def test_the_model_refuses_to_take_over_a_subscription_the_connection_holds(sim: SimThread) -> None:
    async def go() -> str:
        client = await connected(sim.port)
        try:
            client.request("updateNumbers", 100, lambda packet: None)
            entry = entry_of(client.datalist.entry("updateNumbers"))  # type: ignore[arg-type]
            with pytest.raises(ConsoleRefusal, match="already follows"):
                Subscription(client, entry, 100).start()
            change = entry_of(client.datalist.entry("gotoGoal"))  # type: ignore[arg-type]
            with pytest.raises(NeedsConfirmation):
                await call(client, change, FieldWriter().string("Goal").bytes())
            return (await call(client, entry_of(client.datalist.entry("getGoals")), timeout=5)).outcome  # type: ignore[arg-type]
        finally:
            await client.disconnect()

    assert run(go()) == "replied"
    assert console_entries(sim.server.datalist, "goal")  # type: ignore[union-attr]


def test_following_ends_with_the_connection(capsys: pytest.CaptureFixture[str]) -> None:
    thread = ServerThread(TestServer())
    with thread as server:
        end = threading.Timer(1.0, lambda: thread.call(lambda: [server.kill(s) for s in server.sides]))
        end.start()
        try:
            code = main(
                ["call", addr(server.port), "updateNumbers", "--every", "100", "--timeout", cli_timeout(5)]
            )
        finally:
            end.join()
    assert code == EXIT_CONNECTION
    assert "rtmu call:" in capsys.readouterr().err


# -- hostile servers ----------------------------------------------------------------------------------
HOSTILE = [
    *SPECS,
    (
        "listDrawings",
        "drawings",
        "none",
        "byte4: numDrawings, <repeats> string: name",
        "SensorInfo",
        "RETURN_SINGLE",
    ),
    ("manyFields", "a flood", "none", "<repeat> string: item", "Custom", "RETURN_UNTIL_EMPTY"),
    ("endless", "never ends", "none", "string: line", "Custom", "RETURN_UNTIL_EMPTY"),
    ("liar", "a header that lies", "none", "string: value", "Custom", "RETURN_SINGLE"),
    ("hugeArgs", "x", "byte4: x; " * 3000, "none", "Custom", "RETURN_SINGLE"),
]
FLOOD_PACKETS = 7
FLOOD_FIELDS = 15_000


def hostile_server() -> TestServer:
    server = TestServer(HOSTILE)
    lying_count = FieldWriter().byte4(2_000_000_000).string("one").bytes()
    server.handlers["listDrawings"] = lambda s, a: [lying_count]
    server.handlers["manyFields"] = lambda s, a: [b"a\x00" * FLOOD_FIELDS] * FLOOD_PACKETS + [b""]
    server.handlers["endless"] = lambda s, a: [b"x" * 30_000 + b"\x00"] * 200  # 6 MB, no end packet
    server.handlers["hugeArgs"] = lambda s, a: [b"ok\x00"]

    def liar(side: ServerSide, name: str, args: bytes) -> None:
        if name == "liar":  # a header promising 30 000 bytes, then 10 of them and nothing more
            number = side.conn.datalist.number("liar")
            assert number is not None
            side.writer.write(encode_packet(number, b"z" * 3000)[:4] + b"0123456789")

    server.on_once = liar
    return server


def test_hostile_replies_are_bounded() -> None:
    async def go() -> dict[str, object]:
        with ServerThread(hostile_server()) as server:
            client = await connected(server.port)
            try:
                entries = {e.name: e for e in console_entries(client.datalist)}
                lying = await call(client, entries["listDrawings"], timeout=5)
                flood = await call(client, entries["manyFields"], timeout=5)
                endless = await call(client, entries["endless"], timeout=5, max_bytes=1 << 20)
                liar = await call(client, entries["liar"], timeout=1)
                args = entries["hugeArgs"].arguments
                return {"lying": lying, "flood": flood, "endless": endless, "liar": liar, "args": args}
            finally:
                await client.disconnect()

    got = run(go(), timeout=60)
    lying = got["lying"]
    assert lying.outcome == "replied"  # type: ignore[attr-defined]
    view = lying.packets[0]  # type: ignore[attr-defined]
    assert "does not decode" in view.typed_error and view.fields[0].value == 2_000_000_000
    flood = got["flood"]
    assert flood.packet_count >= FLOOD_PACKETS  # type: ignore[attr-defined]
    shown = [p for p in flood.packets if p.size]  # type: ignore[attr-defined]
    assert len(shown) == FLOOD_PACKETS
    assert all(len(p.fields) == MAX_FIELDS_SHOWN for p in shown)
    assert sum(len(p.fields) + p.more_fields for p in shown) == FLOOD_PACKETS * FLOOD_FIELDS > 100_000
    endless = got["endless"]
    assert endless.outcome == "cut" and endless.byte_count < 2 << 20  # type: ignore[attr-defined]
    assert len(endless.packets) <= 16  # type: ignore[attr-defined]
    assert got["liar"].outcome == "silent"  # type: ignore[attr-defined]
    assert len(got["args"].fields) <= 64  # type: ignore[attr-defined]
