"""What a big server configuration (ArConfig) costs a client: decoding, fetching over loopback, memory.

The configuration is the simulator's own plus 10 000 filler parameters (``SimConfig.config_filler``,
markup in every text), served as ``getConfigBySectionsV4`` packets split to fit 32 000 bytes.

* ``config.decode_10k_ms``: the reply's payloads to a bounded ``ServerConfig`` (decode, cut, join the
  parts of each section). Baseline: the payloads through the typed decoder alone, nothing joined.
* ``config.fetch_10k_ms``: connect, ``getLastEditablePriority``, ``getConfigBySectionsV4`` and decode,
  against ``rtmu sim`` on loopback. Baseline: the same for the simulator's plain 11 parameters.
* ``config.decode_10k_peak_kib``: Python's peak allocation while decoding (``tracemalloc``). Baseline:
  the size of the payloads on the wire.
"""

from __future__ import annotations

import asyncio
import time
import tracemalloc

from bench.common import Result, best_time
from rtmu.client.config_feed import assemble, fetch_config
from rtmu.client.connection import AriaClient
from rtmu.protocol.payloads.config import ConfigRequest, ConfigSectionPacket, ParamType, Priority
from rtmu.sim import SimConfig, SimServer, SimThread
from rtmu.values.target import Target

FILLER = 10_000


def _served(server: SimServer) -> int:
    """How many parameters the simulator serves: every one but the separators (only a line)."""
    return sum(p.template.kind is not ParamType.SEPARATOR for p in server.arconfig.params)


def _payloads() -> tuple[list[bytes], int]:
    """The reply's payloads, and how many parameters they carry."""
    server = SimServer(SimConfig(port=0, config_filler=FILLER))
    return server.arconfig.packets(4, ConfigRequest()), _served(server)


def _decode(payloads: list[bytes]) -> int:
    config = assemble([ConfigSectionPacket.decode(p) for p in payloads], Priority.EXPERT, "bench")
    return config.param_count


def _fetch_ms(filler: int, rounds: int = 5) -> float:
    with SimThread(SimConfig(port=0, config_filler=filler, camera=False)) as sim:
        served = sim.call(lambda: _served(sim.server))  # type: ignore[arg-type]

        async def once() -> float:
            client = AriaClient()
            started = time.perf_counter()
            await client.connect(Target("127.0.0.1", sim.port), timeout=10)
            try:
                config = await fetch_config(client, 30)
                assert config.param_count == served, "the fetch lost parameters"
                return (time.perf_counter() - started) * 1000
            finally:
                await client.disconnect()

        return min(asyncio.run(once()) for _ in range(rounds))


def run() -> list[Result]:
    payloads, served = _payloads()
    assert served > FILLER and _decode(payloads) == served, "the decoder lost parameters"
    decode = best_time(lambda: _decode(payloads), repeat=3)
    plain = best_time(lambda: [ConfigSectionPacket.decode(p) for p in payloads], repeat=3)
    tracemalloc.start()
    _decode(payloads)
    _current, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return [
        Result("config.decode_10k_ms", decode * 1000, "ms", baseline=plain * 1000),
        Result("config.fetch_10k_ms", _fetch_ms(FILLER), "ms", baseline=_fetch_ms(0)),
        Result("config.decode_10k_peak_kib", peak / 1024, "KiB", baseline=sum(map(len, payloads)) / 1024),
    ]
