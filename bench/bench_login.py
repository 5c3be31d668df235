"""How long a login takes when the server lists an LD-size data catalogue.

* ``client.login_ms.datalist_1000`` (ms, median of repeated logins): ``AriaClient.connect`` from
  TCP connect to the complete data list, against a loopback server listing 1 000 data whose
  descriptions are 16 000 bytes and argument/return descriptions 7 000 bytes each (Omron LD
  lists have 889 and 989 names; their texts are long). Baseline: the same login against the
  simulator's serverDemo-shaped catalogue (about 80 names, short texts), measured in the same run.

The server is the project's sans-I/O ``ServerConnection`` on 127.0.0.1; each login is a fresh
connection, so the figure includes encoding, the bytes on loopback and the client's decode.
"""

from __future__ import annotations

import asyncio
import statistics
import time

from bench.common import Result
from rtmu.client.connection import AriaClient
from rtmu.protocol.datalist import DataList
from rtmu.protocol.server_connection import ServerConnection
from rtmu.sim.catalogue import build_catalogue
from rtmu.values.target import Target

NAMES = 1000
LOGINS = 15


def ld_size_catalogue() -> DataList:
    """serverDemo's list padded to 1 000 names with long, distinct texts."""
    rows = [
        (e.name, e.description, e.argument_description, e.return_description, e.command_group, e.flags)
        for e in build_catalogue()
    ]
    for i in range(NAMES - len(rows)):
        tag = f"[{i}]"
        rows.append(
            (
                f"DataStore_Item{i:04d}",
                (tag + "d" * 16_000)[:16_000],
                (tag + "a" * 7_000)[:7_000],
                (tag + "r" * 7_000)[:7_000],
                "ExtraData",
                "RETURN_SINGLE",
            )
        )
    return DataList.build(rows)


async def _serve(datalist: DataList, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    conn = ServerConnection(datalist)
    writer.write(conn.data_to_send())
    try:
        while data := await reader.read(65536):
            conn.receive_data(data)
            writer.write(conn.data_to_send())
    except ConnectionError:
        pass
    finally:
        writer.close()


async def _login_ms(datalist: DataList) -> tuple[float, int]:
    server = await asyncio.start_server(lambda r, w: _serve(datalist, r, w), "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    times = []
    names = 0
    try:
        for _ in range(LOGINS):
            client = AriaClient()
            start = time.perf_counter()
            got = await client.connect(Target("127.0.0.1", port), timeout=10)
            times.append((time.perf_counter() - start) * 1000)
            names = len(got)
            await client.disconnect()
    finally:
        server.close()
    return statistics.median(times), names


def run() -> list[Result]:
    demo, big = build_catalogue(), ld_size_catalogue()
    base_ms, demo_names = asyncio.run(_login_ms(demo))
    big_ms, big_names = asyncio.run(_login_ms(big))
    assert demo_names == len(demo) and big_names == NAMES
    return [
        Result("client.login_ms.datalist_serverdemo", base_ms, "ms"),
        Result("client.login_ms.datalist_1000", big_ms, "ms", base_ms),
    ]


if __name__ == "__main__":
    for r in run():
        base = f"  (baseline {r.baseline:.3f})" if r.baseline is not None else ""
        print(f"{r.name:40s} {r.value:10.3f} {r.unit}{base}")
