"""Every data of ``rtmu sim --profile aram`` called through the console, on one loopback connection.

Each call gets its required arguments (zeros and empty strings, typed from the data's own argument
description) and confirmation; each must come back — replied, taken, or reported silent where the
simulator does not answer (LD's configuration data, the server's broadcasts) — without an error,
and the connection must survive them all. ``ratioDrive`` is the one refusal.
"""

from __future__ import annotations

import asyncio

from rtmu.client.connection import AriaClient
from rtmu.client.console import ConsoleEntry, ConsoleRefusal, ConsoleReply, call, console_entries
from rtmu.client.console_layout import encode_arguments
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target

from .servers import run

OFFICE = project_map("office.map")
PER_CALL = 1.0
OUTCOMES = {"replied", "taken", "sent", "silent", "stalled", "cut"}


def sample_arguments(entry: ConsoleEntry) -> bytes:
    layout = entry.arguments
    if not layout.known:
        return b""
    values = ["" if f.kind == "string" else "0" for f in layout.fields[: layout.required]]
    return encode_arguments(layout, values)


async def call_all(port: int) -> tuple[dict[str, ConsoleReply | str], bool]:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port), timeout=10)
    try:
        entries = console_entries(client.datalist)

        async def one(entry: ConsoleEntry) -> ConsoleReply | str:
            try:
                return await call(client, entry, sample_arguments(entry), confirmed=True, timeout=PER_CALL)
            except ConsoleRefusal as exc:
                return f"refused: {exc}"

        replies = await asyncio.gather(*(one(e) for e in entries))
        client.send("stop")  # whatever the calls set going
        alive = client.connected and bool(await client.request_once("updateNumbers", timeout=5))
        return {e.name: r for e, r in zip(entries, replies, strict=True)}, alive
    finally:
        await client.disconnect()


def test_every_aram_data_is_callable_without_crash_or_hang() -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE)) as sim:
        served = {e.name for e in sim.server.datalist}  # type: ignore[union-attr]
        got, alive = run(call_all(sim.port), timeout=120)
    assert set(got) == served and len(served) > 60
    assert alive, "the connection survived every call"
    refused = {name for name, r in got.items() if isinstance(r, str)}
    assert refused == {"ratioDrive"}, refused
    replies = {name: r for name, r in got.items() if not isinstance(r, str)}
    assert all(r.outcome in OUTCOMES for r in replies.values())
    # Reads the simulator answers came back with their bytes; the rest was said to be silent.
    for name in ("updateNumbers", "getModeInfo", "dockInfo", "getRoutes", "DataStore_WirelessQuality"):
        assert replies[name].outcome == "replied" and replies[name].packets, name
    for name in ("getConfigValues", "configExpandedSectionList", "popupCreate"):
        assert replies[name].outcome == "silent", name
    assert replies["stop"].outcome == "taken"
