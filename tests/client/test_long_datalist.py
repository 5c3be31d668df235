"""Servers with an LD-size data list (about 1 000 names) and descriptions of many kilobytes load
whole: every name, every description to its last byte, over a real loopback login.

The test server is our own (``servers.TestServer`` with a long list), not the simulator's catalogue.
"""

from __future__ import annotations

from rtmu.client.connection import AriaClient
from rtmu.protocol.datalist import DataList
from rtmu.values.target import Target

from .servers import SPECS, ServerThread, TestServer, run

NAMES = 1000
DESCRIPTION = 16_000
ARGS = RETURNS = 7_000
"""A list row (name + description, or arguments + returns) must fit one 32 000-byte packet."""


def long_specs(names: int = NAMES) -> list[tuple[str, str, str, str, str, str]]:
    """SPECS plus numbered LD-style data up to ``names``, each with long, distinct texts."""
    rows = list(SPECS)
    for i in range(names - len(rows)):
        tag = f"[{i}]"
        rows.append(
            (
                f"DataStore_Item{i:04d}",
                (tag + "d" * DESCRIPTION)[:DESCRIPTION],
                (tag + "a" * ARGS)[:ARGS],
                (tag + "r" * RETURNS)[:RETURNS],
                "ExtraData",
                "RETURN_SINGLE",
            )
        )
    return rows


def test_a_thousand_names_with_16_kb_descriptions_load_without_truncation() -> None:
    served = DataList.build(long_specs())
    assert len(served) == NAMES

    async def go() -> DataList:
        with ServerThread(TestServer(long_specs())) as server:
            client = AriaClient()
            got = await client.connect(Target("127.0.0.1", server.port), timeout=10)
            await client.disconnect()
            return got

    got = run(go())
    assert len(got) == NAMES
    for want in served:
        entry = got.entry(want.name)
        assert entry == want, want.name
    longest = got.entry(f"DataStore_Item{NAMES - len(SPECS) - 1:04d}")
    assert longest is not None
    assert len(longest.description) == DESCRIPTION
    assert len(longest.argument_description) == ARGS and len(longest.return_description) == RETURNS
