"""The measured window of ``bench_fleet_scale``: the real application on N robots, in its own process.

``python -m bench.fleet_scale_window MODE SELECTIONS PORT…`` opens the window on one robot per port
(all connected: ``connect_at_most`` = N) with MODE ``shared`` (the window's one guardian, armed for the
selected robot) or ``per_robot`` (a guardian process per robot connection: the old way), and prints
one JSON line:

* ``ready_s``: from the application's start (after the imports, as ``bench_fleet``'s figure) until
  every robot has its status and its map and the robot that may drive (the selected one) is
  guarded — its guardian armed; ``ready_cpu_s``: the CPU time this process and its guardians spent
  meanwhile (on a busy machine the wall time grows, this does not: the two tell load from cost);
* ``guardian_rss_mb`` / ``guardians``: the resident memory of the guardian processes (children of
  this one) and how many there are, once ready;
* ``arming_ms``: for SELECTIONS selections in turn (shared mode), the time from ``Fleet.select`` until
  the guardian is armed for the new robot, and ``arming_cpu_ms`` the CPU time this process and its
  guardian spent on each; ``cold_ms``: the same robot's arming by a guardian process started from
  nothing (what a guardian per selection would cost);
* ``load``: the machine's 1-minute load average at the start.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib  # noqa: E402

from rtmu.fleet.sessions import RobotSession  # noqa: E402
from rtmu.guardian.handle import GuardianHandle  # noqa: E402
from rtmu.guardian.messages import Hello  # noqa: E402
from rtmu.settings.store import DirectRobot  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402
from rtmu.values.target import Target  # noqa: E402

PAGE = os.sysconf("SC_PAGE_SIZE")
TICKS = os.sysconf("SC_CLK_TCK")


def guardians() -> list[tuple[int, float]]:
    """(pid, resident MB) of every live guardian process whose parent is this process."""
    out = []
    me = os.getpid()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            if int(stat[1]) != me or b"rtmu.guardian" not in (entry / "cmdline").read_bytes():
                continue
            pages = int((entry / "statm").read_text().split()[1])
        except (OSError, ValueError, IndexError):
            continue
        out.append((int(entry.name), pages * PAGE / 1e6))
    return out


def cpu_s(pids: list[int]) -> float:
    """CPU seconds of this process (every thread) and of the processes ``pids`` (gone ones count 0)."""
    total = time.process_time()
    for pid in pids:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / TICKS  # utime + stime
    return total


def pump_until(ready, timeout: float, what: str) -> None:  # type: ignore[no-untyped-def]
    ctx = GLib.MainContext.default()
    deadline = time.monotonic() + timeout
    while not ready():
        if time.monotonic() > deadline:
            raise SystemExit(f"timed out waiting for {what}")
        ctx.iteration(False) or time.sleep(0.002)


def guarded(session: RobotSession) -> bool:
    seat = session.runner.session.guardian if session.runner.session is not None else None
    return seat is not None and seat.waiting_reason() is None


def cold_arming_ms(port: int) -> float:
    """A guardian process started from nothing, until logged in to the robot at ``port``."""
    t0 = time.monotonic()
    handle = GuardianHandle.start(Hello(Target("127.0.0.1", port), serial=1))
    try:
        while handle.state == "starting":
            handle.poll()
            if time.monotonic() - t0 > 30:
                raise SystemExit("a cold guardian did not log in within 30 s")
            time.sleep(0.002)
        return (time.monotonic() - t0) * 1000.0
    finally:
        handle.close(goodbye=True)


def main(mode: str, selections: int, ports: list[int]) -> None:
    started = time.monotonic()
    cpu_started = time.process_time()
    load = float(Path("/proc/loadavg").read_text().split()[0])
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", p) for i, p in enumerate(ports))
    config = Path(tempfile.mkdtemp(prefix="rtmu-bench-scale-")) / "settings.toml"
    options = GuiOptions(
        fleet=robots,
        settings_path=config,
        persist=False,
        connect_at_most=len(ports),
        guardian_per_robot=mode == "per_robot",
    )
    app = RtmuApplication(options)
    app.register(None)
    app.activate()
    fleet = app.fleet

    def ready() -> bool:
        selected = fleet.selected.value
        every = all(s.state.robot.value.numbers_at is not None and s.state.map.value.state == "ready"
                    for s in fleet)  # fmt: skip
        return len(fleet) == len(ports) and every and selected is not None and guarded(selected)

    pump_until(ready, 600, "the fleet to be ready")
    ready_s = time.monotonic() - started
    ready_cpu_s = cpu_s([pid for pid, _mb in guardians()]) - cpu_started
    end = time.monotonic() + 1.0  # settle: the guardians' logins done, their memory as it stays
    pump_until(lambda: time.monotonic() > end, 10, "time")
    found = guardians()
    arming: list[float] = []
    arming_cpu: list[float] = []
    cold: list[float] = []
    sessions = list(fleet)
    pids = [pid for pid, _mb in found]
    for i in range(selections if mode == "shared" else 0):
        session = sessions[(i + 1) % len(sessions)]
        c0 = cpu_s(pids)
        t0 = time.monotonic()
        fleet.select(session)
        pump_until(lambda s=session: guarded(s), 30, f"the guardian to be armed for {session.name}")
        arming.append((time.monotonic() - t0) * 1000.0)
        arming_cpu.append((cpu_s(pids) - c0) * 1000.0)
    for i in range(min(5, selections) if mode == "shared" else 0):
        cold.append(cold_arming_ms(ports[i % len(ports)]))
    out = {
        "robots": len(ports),
        "mode": mode,
        "ready_s": ready_s,
        "ready_cpu_s": ready_cpu_s,
        "load": load,
        "guardians": len(found),
        "guardian_rss_mb": sum(mb for _pid, mb in found),
        "arming_ms": arming,
        "arming_cpu_ms": arming_cpu,
        "cold_ms": cold,
    }
    print("RESULT " + json.dumps(out), flush=True)
    app.close_session()


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), [int(p) for p in sys.argv[3:]])
