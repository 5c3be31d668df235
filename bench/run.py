"""Run every benchmark, print a table, write ``bench/results.json``.

Usage: ``python -m bench.run [substring ...]`` (only modules whose name contains a substring; a
whole module name — ``bench_fleet`` — picks that module alone, not ``bench_fleet_scale`` too).
"""

from __future__ import annotations

import importlib
import json
import pkgutil
import sys
import traceback
from pathlib import Path

from bench.common import Result

HERE = Path(__file__).resolve().parent


def _picks(wanted: str, module: str) -> bool:
    return wanted == module if wanted.startswith("bench_") else wanted in module


def main(argv: list[str]) -> int:
    wanted = argv[1:]
    results: list[Result] = []
    failed: list[str] = []
    for info in sorted(pkgutil.iter_modules([str(HERE)]), key=lambda m: m.name):
        if not info.name.startswith("bench_") or (wanted and not any(_picks(w, info.name) for w in wanted)):
            continue
        print(f"# {info.name}", file=sys.stderr, flush=True)
        try:
            module = importlib.import_module(f"bench.{info.name}")
            results.extend(module.run())
        except Exception:
            traceback.print_exc()
            failed.append(info.name)
    width = max((len(r.name) for r in results), default=10)
    print(f"{'name':<{width}}  {'value':>14}  {'unit':<12} {'baseline':>14}  {'ratio':>9}")
    for r in results:
        base = f"{r.baseline:14.4g}" if r.baseline is not None else " " * 14
        ratio = f"{r.ratio:9.3g}" if r.ratio is not None else ""
        print(f"{r.name:<{width}}  {r.value:14.4g}  {r.unit:<12} {base}  {ratio}")
    out = HERE / "results.json"
    previous: list[dict[str, object]] = []
    if wanted and out.exists():
        # A partial run keeps the other modules' figures.
        names = {r.name for r in results}
        previous = [e for e in json.loads(out.read_text()) if e.get("name") not in names]
    entries = previous + [r.as_json() for r in results]
    entries.sort(key=lambda e: str(e["name"]))
    out.write_text(json.dumps(entries, indent=2) + "\n")
    print(f"wrote {out} ({len(entries)} figures)", file=sys.stderr)
    if failed:
        print(f"benchmarks that failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
