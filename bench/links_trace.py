"""Where did a false stop's time go? Reads the traces ``bench.links_rig_proc`` writes.

``RTMU_LINKS_TRACE=DIR python -m bench.bench_links false`` (or a shorter soak) leaves one
``rig-*.json`` per simulator; ``python -m bench.links_trace DIR`` prints, for every stop that reached
a simulator, the status stream of each connection in the second before it, with its three clocks:

* ``sim`` — the simulator wrote the status (late: its send loop was starved — the kernel's account
  of its thread over the longest gap says whether it ran its own work, waited for a CPU, or
  neither: blocked, e.g. on the interpreter lock);
* ``read`` / ``due`` / ``out`` — the proxy read it, meant to forward it (its Wi-Fi profile's hold),
  and did (``out - due`` late: the proxy — the lab, not RTMU — was the stall);
* the stop itself; a connection whose bytes went ``out`` well inside the limit before the stop was
  a client that read late.

Then one line per stop: the largest gap each clock shows in that second — the late one is the cause.
"""

from __future__ import annotations

import itertools
import json
import sys
from pathlib import Path

WINDOW = 1.0
STATUS = ("update", "updateNumbers")


def _gaps(times: list[float]) -> float:
    return max((b - a for a, b in itertools.pairwise(times)), default=0.0)


def explain(record: dict, verbose: bool) -> list[str]:
    out: list[str] = []
    sims: dict[str, list[tuple[float, float, float, float]]] = {}
    for at, port, name, world, *account in record["sim"]:
        if name in STATUS:
            ran, waited = account or (0.0, 0.0)
            sims.setdefault(str(port), []).append((at, world, ran, waited))
    chunks: dict[str, list[tuple[float, float, float]]] = {}
    for direction, port, read, due, written, _n in record["proxy"] or []:
        if direction == "to_client":
            chunks.setdefault(str(port), []).append((read, due, written))
    for t, who in record["stops"]:
        for port, sent in sims.items():
            near = [s for s in sent if t - WINDOW <= s[0] <= t]
            if len(near) < 3:
                continue
            sim_times = [s[0] for s in near]
            worst = max(range(1, len(near)), key=lambda i: near[i][0] - near[i - 1][0])
            ran = near[worst][2] - near[worst - 1][2]
            waited = near[worst][3] - near[worst - 1][3]
            offsets = [s[0] - s[1] for s in near]  # monotonic minus simulated time: grows when starved
            got = [c for c in chunks.get(port, []) if t - WINDOW <= c[0] <= t + 0.5]
            reads = [c[0] for c in got if c[0] <= t]
            outs = [c[2] for c in got if c[2] <= t]
            late_out = max((c[2] - c[1] for c in got if c[2] <= t), default=0.0)
            last_out = t - max(outs, default=t - WINDOW)
            gc_ms = sum(d for at, d, _g in record.get("gc", []) if t - WINDOW <= at <= t) * 1000
            out.append(
                f"stop {t:.3f} by {who} port {port}: sim gap {_gaps(sim_times) * 1000:.0f} ms "
                f"(behind {(max(offsets) - min(offsets)) * 1000:.0f} ms; its thread ran {ran * 1000:.0f} ms, "
                f"waited for a CPU {waited * 1000:.0f} ms), proxy read gap "
                f"{_gaps(reads) * 1000:.0f} ms, out gap {_gaps(outs) * 1000:.0f} ms, out late "
                f"{late_out * 1000:.0f} ms, nothing out for {last_out * 1000:.0f} ms before the stop; "
                f"garbage collection {gc_ms:.0f} ms"
            )
            if verbose:
                for read, due, written in got:
                    out.append(
                        f"    read {read - t:+.3f} due {due - t:+.3f} out {written - t:+.3f}"
                        f" (held {1000 * (due - read):.0f} ms, late {1000 * (written - due):.0f} ms)"
                    )
                out.append("    sim " + " ".join(f"{s - t:+.3f}" for s in sim_times))
    return out


def main(argv: list[str]) -> int:
    verbose = "-v" in argv
    for path in sorted(Path(argv[0]).glob("rig-*.json")):
        print(f"# {path.name}")
        for line in explain(json.loads(path.read_text()), verbose):
            print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
