"""The parts ``bench_links`` drives: a simulator behind the fault proxy, the driving processes.

* :class:`Rig` — a :class:`~rtmu.sim.SimThread` with the tests' :class:`FaultProxy` in front, both
  in this process; the simulator's ``stop`` log is watched from a thread so the moment a stop
  arrives is known to a few ms (``time.monotonic()``, one clock for every process).
* :class:`CoreParent` — ``bench.links_parent`` (the window's client core with a UI thread) and the
  stops it reports.
* :func:`drive` — ``rtmu drive`` through the rig, as a script would run it.

``fixed=True`` runs a process with ``RTMU_LINK_TIMING=fixed``: the thresholds RTMU had before it
learned them (and no lease keeper) — the baseline measured in the same run.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from bench.common import end_by_stdin
from rtmu.base.link_timing import FIXED_ENV
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from linkfaults import PROFILES, FaultProxy  # noqa: E402

ARENA = project_map("arena.map")
POLL = 0.002


def env_for(fixed: bool) -> dict[str, str]:
    env = dict(os.environ)
    if fixed:
        env[FIXED_ENV] = "fixed"
    else:
        env.pop(FIXED_ENV, None)
    return env


class Rig:
    """Simulator + proxy; ``stops`` are the monotonic times stops reached the simulator (with who
    sent them: a client's self identifier, ``rtmu-guardian``, or ``watchdog`` for the server's own)."""

    def __init__(self, seed: int = 1) -> None:
        self.sim = SimThread(SimConfig(port=0, map_path=ARENA, seed=seed, max_clients=10)).start()
        self.proxy = FaultProxy("127.0.0.1", self.sim.port).start()
        self.stops: list[tuple[float, str]] = []
        self._closed = threading.Event()
        self._watch = threading.Thread(target=self._watch_stops, daemon=True)
        self._watch.start()

    def _watch_stops(self) -> None:
        log = self.sim.server.stop_log
        ratio_mode = self.sim.server.world.ratio_mode
        seen, watchdog = len(log), ratio_mode.timeouts
        while not self._closed.is_set():
            n = len(log)
            if n > seen:
                now = time.monotonic()
                self.stops += [(now, who or "client") for _t, _ident, who in list(log)[seen - n :]]
                seen = n
            if ratio_mode.timeouts > watchdog:  # the server's own 2 s watchdog stopped it
                watchdog = ratio_mode.timeouts
                self.stops.append((time.monotonic(), "watchdog"))
            time.sleep(POLL)

    @property
    def port(self) -> int:
        """Where a client connects: the proxy."""
        return self.proxy.port

    def play(self, profile: str, seed: int) -> None:
        self.proxy.play(PROFILES[profile], seed=seed)

    def turning(self) -> bool:
        return self.sim.snapshot().rot_ratio != 0

    def drives(self) -> int:
        """ratioDrive packets the simulator has received."""
        return int(self.sim.server.world.ratio_drives_received)

    def stop_after(self, t0: float, timeout: float) -> float | None:
        """The first stop that reached the simulator at or after ``t0`` (waiting up to ``timeout``)."""
        deadline = time.monotonic() + timeout
        while True:
            for at, _who in list(self.stops):
                if at >= t0:
                    return at
            if time.monotonic() > deadline:
                return None
            time.sleep(POLL)

    def moving(self) -> bool:
        return self.sim.snapshot().trans_ratio != 0

    def wait(self, cond, timeout: float) -> bool:  # type: ignore[no-untyped-def]
        deadline = time.monotonic() + timeout
        while not cond():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def close(self) -> None:
        self._closed.set()
        self.proxy.close()
        self.sim.stop()


class RigProcess:
    """A :class:`Rig` in its own process (``bench.links_rig_proc``), with the same questions."""

    def __init__(self, seed: int = 1) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "bench.links_rig_proc", str(seed)],
            cwd=REPO,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            start_new_session=True,  # a scheduling group of its own (base.priority.raise_group_priority)
        )
        assert self.proc.stdout is not None
        word, port = self.proc.stdout.readline().split()
        if word != "port":
            raise RuntimeError("the rig did not start")
        self.port = int(port)
        self.stops: list[tuple[float, str]] = []
        self._states: list[tuple[float, float, int]] = []
        self._cond = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            parts = line.split()
            with self._cond:
                if parts[:1] == ["stop"]:
                    self.stops.append((float(parts[1]), parts[2]))
                elif parts[:1] == ["state"]:
                    self._states.append((float(parts[1]), float(parts[2]), int(parts[3])))
                self._cond.notify_all()

    def _send(self, line: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()

    def play(self, profile: str, seed: int) -> None:
        self._send(f"play {profile} {seed}")

    def reset_pose(self) -> None:
        self._send("reset")

    def state(self) -> tuple[float, float, int]:
        """(commanded trans ratio, rot ratio, ratioDrive packets so far), asked now."""
        with self._cond:
            n = len(self._states)
            self._send("state")
            self._cond.wait_for(lambda: len(self._states) > n, 10)
            return self._states[-1]

    def moving(self) -> bool:
        return self.state()[0] != 0

    def turning(self) -> bool:
        return self.state()[1] != 0

    def drives(self) -> int:
        return self.state()[2]

    def wait(self, cond, timeout: float) -> bool:  # type: ignore[no-untyped-def]
        deadline = time.monotonic() + timeout
        while not cond():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.02)
        return True

    def close(self) -> None:
        end_by_stdin(self.proc)


class CoreParent:
    """``bench.links_parent`` through ``port``; its reported stops and guardian stops, timestamped."""

    def __init__(self, port: int, *, fixed: bool) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "bench.links_parent", str(port)],
            cwd=REPO,
            env=env_for(fixed),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        self.stops: list[tuple[float, str]] = []
        self.guardian: list[tuple[float, str]] = []
        self.logs: list[tuple[float, str]] = []
        """Its ``rtmu`` log lines (each stop's measured account), timestamped."""
        self.ui_tid = 0
        self._driving = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()
        if not self._driving.wait(30):
            self.close()
            raise RuntimeError("the driving process did not start")

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            word, _, rest = line.strip().partition(" ")
            if word == "ui":
                self.ui_tid = int(rest)
            elif word == "driving":
                self._driving.set()
            elif word == "log":
                at, _, text = rest.partition(" ")
                self.logs.append((float(at), text))
            elif word in ("stop", "guardian"):
                at, _, text = rest.partition(" ")
                (self.stops if word == "stop" else self.guardian).append((float(at), text))

    def send(self, *words: object) -> None:
        assert self.proc.stdin is not None
        with contextlib.suppress(OSError):
            self.proc.stdin.write(" ".join(str(w) for w in words) + "\n")
            self.proc.stdin.flush()

    def stop_after(self, t0: float, timeout: float) -> tuple[float, str] | None:
        deadline = time.monotonic() + timeout
        while True:
            for at, text in list(self.stops):
                if at >= t0:
                    return at, text
            if time.monotonic() > deadline:
                return None
            time.sleep(POLL)

    def close(self) -> None:
        self.send("quit")
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5)


def drive(port: int, seconds: float, *, fixed: bool) -> tuple[int, str]:
    """``rtmu drive`` for ``seconds`` through ``port``: (exit code, stderr)."""
    args = [sys.executable, "-m", "rtmu", "drive", f"127.0.0.1:{port}", "--trans", "30"]
    args += ["--seconds", f"{seconds:.1f}", "--timeout", "10"]
    done = subprocess.run(args, env=env_for(fixed), capture_output=True, text=True, timeout=seconds + 60)
    return done.returncode, done.stderr
