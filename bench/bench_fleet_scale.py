"""A fleet that scales: one guardian for the window, a bounded number of robots connected, a huge list.

Each figure's ``baseline`` is the old way, measured in the same run where it still runs: a guardian
process per robot connection (``GuiOptions.guardian_per_robot``) and, for a central server, every
listed robot connected (``connect_at_most`` 1000).

* ``fleet_scale.ready_s.{1,20,50}_robots`` (s): the window process's start until every robot has its
  status and its map and the selected robot is guarded (``bench.fleet_scale_window``). Targets:
  20 robots within 2 s, 50 within 5 s. ``…ready_cpu_s…`` (s): the CPU time the window process and its
  guardians spent meanwhile — what the start costs, whatever else loads the machine.
* ``fleet_scale.guardian_rss_mb.{1,20,50}_robots`` (MB) and ``…guardian_processes…``: the guardian
  processes' resident memory and number once ready — independent of the fleet's size.
* ``fleet_scale.arming_on_selection_ms.{p50,p95,max}`` (ms): ``Fleet.select`` of another robot of a
  20-robot fleet until the window's guardian is armed for it (target 300 ms); baseline: a guardian
  process started from nothing until logged in (what a guardian per selection would cost).
  ``…arming_cpu_ms.p50`` (ms): the CPU time the window and its guardian spent on one arming.
* ``fleet_scale.guardian_arming_100ms_rtt_ms.{p50,p95}`` (ms): the guardian process armed for a robot
  behind a link of 100 ms round trip (``tests/linkfaults.py``'s proxy, as over a slow Wi-Fi), from
  its LOGIN until it says ready, for a robot whose login it kept ready (the robot selected before or
  beside the selection, named a second before) — baseline: a robot it had no login to (a new login:
  connection, introduction, data list).

Each window runs ``RTMU_BENCH_FLEET_SCALE_RUNS`` times (3) on the same simulators; a figure is the
median of its runs (the machine is shared: one run says little).
* ``fleet_scale.central_{100,10000}_listed.key_ms.{p50,p95,max}`` (ms): Space pressed through XTEST
  every 0.2 s for 8 s from the window's first frame, while the central server's list pours in, until
  the controller's ``stop`` runs (``bench.central_window``); ``…sigterm_s``: SIGTERM until the
  process has exited; ``…connections``: robot sessions the window opened. 10 000 listed cannot be
  run the old way here (1 000 sessions and guardian processes, ~27 GB): its baselines are issue 25's
  figures (SIGTERM ignored for 15 s; 2 097 connections).

Needs Xvfb (started here when ``DISPLAY`` is unset) and xdotool. ``RTMU_BENCH_FLEET_SCALE_OLD=0``
skips the old way's runs (they load the machine: 50 guardian processes, 100 sessions).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from bench.bench_fleet import _display, _sims
from bench.common import Result
from rtmu.guardian.handle import GuardianHandle
from rtmu.guardian.messages import Hello
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.central_listing import ListingCentralThread
from rtmu.values.target import Target

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from linkfaults import FaultProxy  # noqa: E402

SIZES = (1, 20, 50)
SELECTIONS = 20
CENTRAL_LISTED = (100, 10_000)
KEY_SECONDS = 8.0
ARMINGS = 10
WIFI_DELAY = 0.05
"""Seconds each way through the proxy: a 100 ms round trip."""
OLD = os.environ.get("RTMU_BENCH_FLEET_SCALE_OLD", "1") != "0"
RUNS = max(1, int(os.environ.get("RTMU_BENCH_FLEET_SCALE_RUNS", "3")))
ISSUE_SIGTERM_S = 15.0
"""Issue 25: with a central server listing ~100 robots the window ignored SIGTERM for 15 s."""
ISSUE_CONNECTIONS_10000 = 2097.0
"""Issue 25: with 10 000 listed (1 000 kept) the window opened 2 097 robot connections."""


HOME = Path(tempfile.gettempdir()) / f"rtmu-bench-scale-{os.getpid()}"
"""The windows' recordings and settings, apart from the user's (removed at the end of the run)."""


def _env(display: str) -> dict[str, str]:
    """The window's environment: its display, and its recordings and settings in a place of their own."""
    home = str(HOME)
    return dict(os.environ, DISPLAY=display, GSK_RENDERER="cairo", NO_AT_BRIDGE="1", GDK_BACKEND="x11",
                XDG_DATA_HOME=home, XDG_CONFIG_HOME=home)  # fmt: skip


def _result(stdout: str, stderr: str, code: int | None) -> dict[str, object]:
    found = re.search(r"^RESULT (.*)$", stdout, re.MULTILINE)
    if found is None:
        raise RuntimeError(f"the window gave no figures (exit {code}): {stderr[-2000:]}")
    return dict(json.loads(found.group(1)))


def fleet_window(mode: str, ports: list[int], display: str) -> dict[str, object]:
    argv = [sys.executable, "-m", "bench.fleet_scale_window", mode, str(SELECTIONS), *map(str, ports)]
    out = subprocess.run(argv, cwd=REPO, env=_env(display), capture_output=True, text=True, timeout=900)
    return _result(out.stdout, out.stderr, out.returncode)


def central_window(mode: str, port: int, display: str) -> dict[str, object]:
    """The window on a central server: its key latencies, then SIGTERM until it has exited."""
    argv = [sys.executable, "-m", "bench.central_window", mode, str(KEY_SECONDS), f"127.0.0.1:{port}"]
    proc = subprocess.Popen(argv, cwd=REPO, env=_env(display), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip
    assert proc.stdout is not None
    try:
        lines: list[str] = []
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            if line.startswith("RESULT "):
                break
        figures = _result("".join(lines), "", proc.poll())
        t0 = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(120)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
        figures["sigterm_s"] = time.monotonic() - t0
        return figures
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def median_runs(runs: list[dict[str, object]]) -> dict[str, object]:
    """One window's figures as the median of its runs: a number's median, and for each list of
    samples the run whose own median is the median run's (its percentiles are kept whole)."""
    if len(runs) == 1:
        return runs[0]
    out: dict[str, object] = {}
    for key, first in runs[0].items():
        if isinstance(first, (int, float)) and not isinstance(first, bool):
            out[key] = float(np.median([float(r[key]) for r in runs]))  # type: ignore[arg-type]
        elif isinstance(first, list) and first:
            ranked = sorted(runs, key=lambda r: _pct(r[key], 50))  # type: ignore[arg-type]
            out[key] = ranked[len(ranked) // 2][key]
        else:
            out[key] = first
    return out


def _stats(name: str, values: list[float], baseline: list[float] | None) -> list[Result]:
    return [
        Result(f"{name}.{label}", _pct(values, q), "ms", _pct(baseline, q) if baseline else None)
        for label, q in (("p50", 50), ("p95", 95), ("max", 100))
    ]


def _num(figures: dict[str, object] | None, key: str) -> float | None:
    return None if figures is None else float(figures[key])  # type: ignore[arg-type]


def _nums(figures: dict[str, object] | None, key: str) -> list[float] | None:
    return None if figures is None else [float(v) for v in figures[key]]  # type: ignore[attr-defined]


def fleet_results(display: str) -> list[Result]:
    results: list[Result] = []
    for n in SIZES:
        with _sims(n) as ports:
            fleet_window("shared", ports, display)  # the simulators' first clients: not measured
            new = median_runs([fleet_window("shared", ports, display) for _ in range(RUNS)])
            old = None
            if OLD:
                old = median_runs([fleet_window("per_robot", ports, display) for _ in range(RUNS)])
        tag = f"{n}_robot" if n == 1 else f"{n}_robots"
        for key, name, unit in (
            ("ready_s", "ready_s", "s"),
            ("ready_cpu_s", "ready_cpu_s", "s"),
            ("guardian_rss_mb", "guardian_rss_mb", "MB"),
            ("guardians", "guardian_processes", "processes"),
        ):
            results.append(Result(f"fleet_scale.{name}.{tag}", _num(new, key) or 0.0, unit, _num(old, key)))
        if n == 20:
            arming = _nums(new, "arming_ms") or []
            results += _stats("fleet_scale.arming_on_selection_ms", arming, _nums(new, "cold_ms"))
            cpu = _nums(new, "arming_cpu_ms") or []
            results.append(Result("fleet_scale.arming_cpu_ms.p50", _pct(cpu, 50), "ms"))
    return results


def central_results(display: str) -> list[Result]:
    results: list[Result] = []
    with _sims(2) as ports:
        for listed in CENTRAL_LISTED:
            with ListingCentralThread(listed, ports) as central:
                new = central_window("bounded", central.port, display)
            old = None
            if OLD and listed <= 100:
                with ListingCentralThread(listed, ports) as central:
                    old = central_window("unbounded", central.port, display)
            name = f"fleet_scale.central_{listed}_listed"
            results += _stats(f"{name}.key_ms", _nums(new, "key_ms") or [], _nums(old, "key_ms"))
            sigterm = _num(old, "sigterm_s") if old is not None else ISSUE_SIGTERM_S
            connections = _num(old, "connected") if old is not None else ISSUE_CONNECTIONS_10000
            results.append(Result(f"{name}.sigterm_s", _num(new, "sigterm_s") or 0.0, "s", sigterm))
            opened = _num(new, "connected") or 0.0
            results.append(Result(f"{name}.connections", opened, "sessions", connections))
    return results


def _armed_ms(handle: GuardianHandle, hello: Hello) -> float:
    """LOGIN to ``hello``'s robot until the guardian says it is ready, in ms."""
    t0 = time.monotonic()
    handle.login(hello)
    while True:
        for word, serial, text in handle.poll():
            if serial == hello.serial and word == "ready":
                return (time.monotonic() - t0) * 1000.0
            if serial == hello.serial:
                raise RuntimeError(f"the guardian could not log in: {word} {text}")
        if time.monotonic() - t0 > 30:
            raise RuntimeError("the guardian did not log in within 30 s")
        time.sleep(0.001)


def arming_results() -> list[Result]:
    """The guardian's arming over a 100 ms round trip: a login kept ready against a new one."""
    kept: list[float] = []
    cold: list[float] = []
    with (
        SimThread(SimConfig(port=0)) as a,
        SimThread(SimConfig(port=0)) as b,
        FaultProxy("127.0.0.1", a.port) as to_a,
        FaultProxy("127.0.0.1", b.port) as to_b,
    ):
        to_a.delay(WIFI_DELAY)
        to_b.delay(WIFI_DELAY)
        handle = GuardianHandle.start()
        try:
            for serial in range(1, 2 * ARMINGS + 1):
                robot = Hello(Target("127.0.0.1", (to_a if serial % 2 else to_b).port))  # the two in turn
                if serial <= ARMINGS:  # a new login each time: its kept login is let go of first (COLD)
                    handle.cool(robot)
                    cold.append(_armed_ms(handle, replace(robot, serial=serial)))
                else:  # named a second before, as the window names the robots beside the selection
                    handle.warm(robot)
                    time.sleep(1.0)
                    kept.append(_armed_ms(handle, replace(robot, serial=serial)))
        finally:
            handle.close(goodbye=True)
    name = "fleet_scale.guardian_arming_100ms_rtt_ms"
    return [
        Result(f"{name}.{label}", _pct(kept, q), "ms", _pct(cold, q))
        for label, q in (("p50", 50), ("p95", 95))
    ]


def run() -> list[Result]:
    try:
        with _display() as display:
            return fleet_results(display) + arming_results() + central_results(display)
    except FileNotFoundError:
        print("# fleet_scale: no Xvfb: figures skipped", file=sys.stderr)
        return []
    finally:
        shutil.rmtree(HOME, ignore_errors=True)


if __name__ == "__main__":
    with contextlib.suppress(KeyboardInterrupt):
        for r in run():
            print(json.dumps(r.as_json()))
