"""The simulator's configuration on the wire: by sections, validated, live, broadcast (manual clock)."""

from __future__ import annotations

from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads.config import (
    ConfigRequest,
    ConfigSectionPacket,
    ConfigSectionPacketV2,
    ConfigSectionPacketV3,
    ParamType,
    Priority,
    SetConfig,
    SetConfigReply,
)
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.arconfig import FILLER_PER_SECTION
from testdata import CAPTURES

from .wire import WireClient, captured_datalist, run

CAPTURE = CAPTURES / "clientCommandLister-serverDemoMap.pcap"


async def _start(**kw) -> tuple[SimServer, WireClient]:
    server = SimServer(SimConfig(port=0, realtime=False, **kw))
    await server.start()
    return server, await WireClient().open(server.port)


async def _end(server: SimServer, *clients: WireClient) -> None:
    for c in clients:
        await c.close()
    await server.stop()


async def fetch(c: WireClient, name: str = "getConfigBySectionsV4", args: bytes | None = None) -> list[bytes]:
    c.received[name].clear()
    c.once(name, ConfigRequest().encode() if args is None else args)
    await c.until(lambda: b"" in c.received[name], timeout=30)
    return list(c.received[name])


async def set_config(c: WireClient, changes: dict[str, dict[str, str]]) -> str:
    before = len(c.received["setConfig"])
    c.once("setConfig", SetConfig.of(changes).encode())
    got = await c.wait_for("setConfig", before + 1)
    return SetConfigReply.decode(got[-1]).error


def values(packets: list[bytes], cls: type[ConfigSectionPacket] = ConfigSectionPacket) -> dict[str, object]:
    out: dict[str, object] = {}
    for raw in packets:
        packet = cls.decode(raw)
        for p in packet.params:
            if p.kind is not ParamType.SEPARATOR:
                out[f"{packet.name}/{p.name}"] = p.value
    return out


def test_the_simulator_lists_the_config_data_as_serverdemo_does() -> None:
    from rtmu.sim.catalogue import CONFIG

    captured = {e.name: e for e in captured_datalist(CAPTURE)}
    for row in CONFIG:
        entry = captured[row[0]]
        assert row[1:] == (
            entry.description,
            entry.argument_description,
            entry.return_description,
            entry.command_group,
            entry.flags,
        ), row[0]


def test_sections_and_values_reflect_the_live_simulation() -> None:
    async def scenario() -> None:
        server, c = await _start()
        packets = await fetch(c)
        assert packets[-1] == b"" and all(len(p) <= MAX_PAYLOAD for p in packets)
        names = [ConfigSectionPacket.decode(p).name for p in packets[:-1]]
        assert names == ["Teleop", "Robot config", "Camera", "Battery", "Wi-Fi", "Files"]
        got = values(packets)
        assert got["Teleop/Timeout"] == 2.0 and got["Camera/FrameSize"] == "320x240"
        assert got["Robot config/SerialNumber"] == "SIM-P3DX-0001"  # factory: shown because asked for
        timeout = ConfigSectionPacket.decode(packets[0]).params[0]
        assert (timeout.minimum, timeout.maximum, timeout.priority) == (0.0, 60.0, Priority.INTERMEDIATE)
        assert "seconds" in timeout.description
        # an old client (no args) sees no parameter above what the server lets it edit
        assert "Robot config/SerialNumber" not in values(await fetch(c, args=b""))
        assert "Wi-Fi/WallLoss" in values(await fetch(c, "getConfigBySectionsV2", b""), ConfigSectionPacketV2)
        await _end(server, c)

    run(scenario())


def test_a_shorter_drive_timeout_stops_a_lone_ratio_drive_sooner() -> None:
    async def scenario() -> None:
        server, c = await _start()
        assert await set_config(c, {"Teleop": {"Timeout": "0.5"}}) == ""
        assert server.world.ratio_mode.timeout == 0.5
        c.once("ratioDrive", RatioDrive(50, 0, 100).encode())
        await c.barrier()
        await server.advance(0.4)
        assert server.world.ratio_mode.timeouts == 0 and server.robot.vel > 0
        await server.advance(0.3)
        assert server.world.ratio_mode.timeouts == 1
        assert server.robot.trans_ratio == 0  # the watchdog zeroed the ratios at 0.5 s, not ARIA's 2 s
        await _end(server, c)

    run(scenario())


def test_a_lower_speed_limit_caps_a_full_stick_drive() -> None:
    async def scenario() -> None:
        server, c = await _start()
        assert await set_config(c, {"Robot config": {"TransVelMax": "200", "RotVelMax": "10"}}) == ""
        for _ in range(30):  # hold full forward and full left for 3 s
            c.once("ratioDrive", RatioDrive(100, 100, 100).encode())
            await c.barrier()
            await server.advance(0.1)
        assert 150 <= server.robot.vel <= 200
        assert 0 < server.robot.rot_vel <= 10
        await _end(server, c)

    run(scenario())


def test_camera_size_battery_and_wifi_take_effect() -> None:
    async def scenario() -> None:
        server, c = await _start()
        answer = await set_config(
            c,
            {
                "Camera": {"FrameSize": "640x480"},
                "Battery": {"DrainScale": "500"},
                "Wi-Fi": {"TxAt1m": "-60", "WallLoss": "0"},
            },
        )
        assert answer == ""
        assert server.video_size == (640, 480)
        assert server.world.body.drain_scale == 500
        assert server.world.access_point.link(0.0, 0.0).signal_dbm <= -60
        v0 = server.world.body.battery_v
        await server.advance(10.0)
        drained = v0 - server.world.body.battery_v
        assert await set_config(c, {"Battery": {"Drain": "false"}}) == ""
        v1 = server.world.body.battery_v
        await server.advance(10.0)
        assert drained > 0 and server.world.body.battery_v == v1
        await _end(server, c)

    run(scenario())


def test_a_refused_value_names_the_parameter_and_changes_nothing() -> None:
    async def scenario() -> None:
        server, c = await _start()
        cases = {
            "Teleop/Timeout: 99 is above the maximum of 60": {"Teleop": {"Timeout": "99"}},
            "Teleop/Timeout: 'soon' is not a number": {"Teleop": {"Timeout": "soon"}},
            "Robot config/TransVelMax: '1.5' is not a whole number": {"Robot config": {"TransVelMax": "1.5"}},
            "Camera/FrameSize: '800x600' is not one of 320x240, 640x480": {
                "Camera": {"FrameSize": "800x600"}
            },
            "Battery/Drain: 'maybe' is not true or false": {"Battery": {"Drain": "maybe"}},
            "Teleop/Nothing: there is no such parameter": {"Teleop": {"Nothing": "1"}},
            "Teleop/Timeout: 0.05 s is shorter than the 0.1 s between ratioDrive commands (0 disables it)": {
                "Teleop": {"Timeout": "0.05"}
            },
            "Robot config/SerialNumber: a factory parameter cannot be changed here": {
                "Robot config": {"SerialNumber": "X"}
            },
        }
        for expected, changes in cases.items():
            assert await set_config(c, changes) == expected
        # one good and one bad value: the good one is not taken either
        both = {"Teleop": {"Timeout": "1"}, "Camera": {"FrameSize": "1x1"}}
        assert "FrameSize" in await set_config(c, both)
        assert server.world.ratio_mode.timeout == 2.0 and server.video_size == (320, 240)
        assert server.arconfig.sets == 0
        await _end(server, c)

    run(scenario())


def test_a_change_is_broadcast_to_the_other_clients_only() -> None:
    async def scenario() -> None:
        server, a = await _start()
        b = await WireClient().open(server.port)
        for c in (a, b):
            c.request("configUpdated", -1)
            await c.barrier()
        assert await set_config(a, {"Teleop": {"Timeout": "1"}}) == ""
        await b.wait_for("configUpdated")
        await a.barrier()
        assert a.received["configUpdated"] == [] and b.received["configUpdated"] == [b""]
        assert await set_config(a, {"Teleop": {"Timeout": "1"}}) == ""  # nothing changed: no broadcast
        assert await set_config(a, {"Teleop": {"Timeout": "99"}}) != ""  # refused: none either
        await b.barrier()
        assert len(b.received["configUpdated"]) == 1
        await _end(server, a, b)

    run(scenario())


def test_ten_thousand_parameters_come_in_section_parts_that_fit_a_packet() -> None:
    async def scenario() -> None:
        server, c = await _start(config_filler=10_000)
        packets = await fetch(c)
        assert all(len(p) <= MAX_PAYLOAD for p in packets)
        decoded = [ConfigSectionPacket.decode(p) for p in packets[:-1]]
        filler = [p for d in decoded for p in d.params if d.name.startswith("<b>Extra")]
        assert len(filler) == 10_000
        parts = [d.index for d in decoded if d.name == "<b>Extra</b> & 0"]
        assert len(parts) >= 2 and parts == list(range(1, len(parts) + 1))  # too big for one packet
        assert sum(len(d.params) for d in decoded if d.name == "<b>Extra</b> & 0") == FILLER_PER_SECTION
        # V3 splits the same way; a hostile value is set like any other
        assert len(await fetch(c, "getConfigBySectionsV3")) > len(decoded) // 2
        assert ConfigSectionPacketV3.decode((await fetch(c, "getConfigBySectionsV3"))[0]).name == "Teleop"
        assert await set_config(c, {"<b>Extra</b> & 0": {"P0<i>&amp;": "7"}}) == ""
        assert values(await fetch(c))["<b>Extra</b> & 0/P0<i>&amp;"] == 7  # the encoded sections follow a set
        await _end(server, c)

    run(scenario(), timeout=120)
