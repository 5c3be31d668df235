"""Shared helpers for the benchmarks: one result shape, a timer, and the JSON writer.

Every benchmark module in ``bench/`` is named ``bench_*.py`` and has a
``run() -> list[Result]``. ``python -m bench.run`` imports them all, prints a
table and writes ``bench/results.json``.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

TICKS = os.sysconf("SC_CLK_TCK")


@dataclass
class Result:
    name: str
    """Stable, dotted, lower-case, e.g. ``codec.status_decode_rate``."""
    value: float
    unit: str
    baseline: float | None = None
    """The simple way, measured in the same run."""

    @property
    def ratio(self) -> float | None:
        if self.baseline in (None, 0):
            return None
        return self.value / self.baseline

    def as_json(self) -> dict[str, object]:
        out: dict[str, object] = {"name": self.name, "value": round(self.value, 6), "unit": self.unit}
        if self.baseline is not None:
            out["baseline"] = round(self.baseline, 6)
            ratio = self.ratio
            if ratio is not None:
                out["ratio"] = round(ratio, 4)
        return out


def best_time(fn: Callable[[], object], *, repeat: int = 5, min_seconds: float = 0.2) -> float:
    """Seconds per call of ``fn``: the best of ``repeat`` rounds, each at least ``min_seconds`` long."""
    calls = 1
    while True:
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        elapsed = time.perf_counter() - t0
        if elapsed >= min_seconds / 4 or calls > 1 << 24:
            break
        calls *= 4
    best = elapsed / calls
    for _ in range(repeat - 1):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - t0) / calls)
    return best


def end_process(proc: subprocess.Popen[Any], grace: float = 10.0) -> None:
    """SIGTERM, then SIGKILL if it has not ended within ``grace`` seconds; always reaped."""
    proc.terminate()
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(5)


def end_by_stdin(proc: subprocess.Popen[Any], grace: float = 10.0) -> None:
    """End a helper whose life is its stdin (it serves until stdin closes): close it, wait ``grace``
    seconds, then SIGKILL; always reaped."""
    if proc.stdin is not None:
        with contextlib.suppress(OSError):
            proc.stdin.close()
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(5)


def start_xvfb() -> tuple[subprocess.Popen[bytes], str]:
    """An Xvfb of our own on a free display (it writes the number to a pipe): (process, ':N')."""
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as f:
        display = f.readline().strip()
    if not display:
        proc.kill()
        raise RuntimeError("Xvfb did not start")
    return proc, f":{display}"


def cpu_seconds(pid: int, *, descendants: bool = True) -> float:
    """utime + stime of ``pid`` and (unless told not to) every live descendant, from ``/proc``."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(entry.name))
    total, todo = 0.0, [pid]
    while todo:
        p = todo.pop()
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / TICKS
        todo += children.get(p, []) if descendants else []
    return total


def as_installed(env: dict[str, str]) -> dict[str, str]:
    """``env`` for a measured process that should start as an installed RTMU does: with its bytecode
    cached. (A session that sets ``PYTHONDONTWRITEBYTECODE`` would otherwise make every start compile
    every module again — a second of CPU in the window's launch.) Call :func:`cache_bytecode` first."""
    out = dict(env)
    out.pop("PYTHONDONTWRITEBYTECODE", None)
    return out


def cache_bytecode() -> None:
    """Compile ``src/rtmu`` and ``bench`` to ``__pycache__`` (as installing a wheel does), quietly."""
    repo = Path(__file__).resolve().parents[1]
    subprocess.run(
        [sys.executable, "-m", "compileall", "-q", str(repo / "src" / "rtmu"), str(repo / "bench")],
        check=False,
        stdout=subprocess.DEVNULL,
    )
