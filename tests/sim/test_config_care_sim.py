"""The simulator's configuration care on the wire: factory values, setConfigParam's answer, reloadConfig."""

from __future__ import annotations

from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads.config import SetConfig
from rtmu.protocol.payloads.configcare import (
    ConfigDefaults,
    ConfigDefaultsRequest,
    SetConfigParam,
    SetConfigParamReply,
)
from rtmu.sim import SimConfig, SimServer

from .wire import WireClient, run


async def _start(**kw) -> tuple[SimServer, WireClient]:
    server = SimServer(SimConfig(port=0, realtime=False, **kw))
    await server.start()
    return server, await WireClient().open(server.port)


def test_factory_values_come_in_one_packet_of_pairs_whole_or_by_section() -> None:
    async def scenario() -> None:
        server, c = await _start()
        c.once("setConfig", SetConfig.of({"Teleop": {"Timeout": "0.5"}}).encode())
        await c.wait_for("setConfig")
        every = ConfigDefaults.decode((await c.ask("getConfigDefaults"))[0]).by_section()
        assert ("Teleop", "Timeout", "2") in every and (
            "Robot config",
            "SerialNumber",
            "SIM-P3DX-0001",
        ) in every
        # a default for every parameter that has a value, and nothing else (no separator)
        assert [(sec, name) for sec, name, _ in every] == [
            (sec, name) for sec, name, _ in server.arconfig.values()
        ]
        assert [(s, n) for s, n, _v in every if s == "Files"] == [("Files", "Map")]  # ARNL's map file
        one = ConfigDefaults.decode(
            (await c.ask("getConfigDefaults", ConfigDefaultsRequest("teleop").encode()))[0]
        )
        assert one.pairs[:2] == (("Section", "Teleop"), ("Timeout", "2"))
        assert {name for name, _value in one.pairs[2:]} == {"ForwardClearance", "BackwardClearance"}
        none = await c.ask("getConfigDefaults", ConfigDefaultsRequest("Nowhere").encode())
        assert none == [b""]
        await c.close()
        await server.stop()

    run(scenario())


def test_a_huge_configuration_is_cut_at_the_last_whole_pair_that_fits() -> None:
    async def scenario() -> None:
        server, c = await _start(config_filler=5000)
        raw = (await c.ask("getConfigDefaults"))[0]
        assert 30_000 < len(raw) <= MAX_PAYLOAD
        pairs = ConfigDefaults.decode(raw).pairs
        assert pairs[:2] == (("Section", "Teleop"), ("Timeout", "2")) and all(len(p) == 2 for p in pairs)
        await c.close()
        await server.stop()

    run(scenario())


def test_set_config_param_answers_the_section_and_the_first_error() -> None:
    async def scenario() -> None:
        server, c = await _start()
        other = await WireClient().open(server.port)
        other.request("configUpdated", -1)
        c.request("configUpdated", -1)
        await other.barrier()
        ok = SetConfigParamReply.decode(
            (await c.ask("setConfigParam", SetConfigParam.of({"Teleop": {"Timeout": "1"}}).encode()))[0]
        )
        assert (ok.section, ok.error) == ("Teleop", "")
        assert server.world.ratio_mode.timeout == 1.0
        await other.wait_for("configUpdated")
        bad = SetConfigParamReply.decode(
            (await c.ask("setConfigParam", SetConfigParam.of({"Teleop": {"Timeout": "99"}}).encode()))[0]
        )
        assert (bad.section, bad.error) == ("Teleop", "Teleop/Timeout: 99 is above the maximum of 60")
        assert server.world.ratio_mode.timeout == 1.0
        c.once("reloadConfig")
        await c.wait_for("configUpdated")  # the asker hears it too, as ARIA broadcasts to everyone
        await other.wait_for("configUpdated", 2)
        assert c.received["reloadConfig"] == []  # no reply
        names = [e.name for e in server.datalist]
        assert names.index("setConfig") + 1 == names.index("setConfigParam") < names.index("reloadConfig")
        await c.close()
        await other.close()
        await server.stop()

    run(scenario())
