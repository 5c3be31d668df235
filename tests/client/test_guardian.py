"""The guardian (``rtmu.guardian``): a stop that survives the process that drives.

A real parent process (the client core: runner + lease + guardian, as the window
builds it) drives the real simulator over loopback; then it is killed, frozen or
closed. The simulator records every ``stop`` with the sender's self identifier,
so each test asserts WHO stopped the robot (the guardian's own connection) and
that the simulator's 2 s watchdog did not have to — never how many ms it took
(``bench/bench_safety.py`` measures that).
"""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.guardian import halt
from rtmu.guardian import messages as m
from rtmu.guardian.child import (
    CHECK_PERIOD,
    QUICK_LATE,
    SILENT_CEILING,
    SILENT_LATE,
    SILENT_LATE_NETWORK,
    FixedLimit,
    Watch,
    learned_limit,
    parent_frozen,
)
from rtmu.guardian.halt import IDENTIFIER, IDENTIFIER_ARGS, ZERO_RATIO_DRIVE
from rtmu.guardian.shared import SeatState
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.server import SelfIdentifier
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target
from simulators import simulator

from .uiqueue import eventually

PASSWORD = "guardianSecret7f3a"
GUARDIAN_DIR = Path(halt.__file__).parent

PARENT = r"""
import sys, threading, time
from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.values.target import Target
port, user, password, guardian, drive = sys.stdin.readline().split()
runner = ClientRunner(config=SessionConfig(fetch_map=False, guardian=guardian == "1")).start()
runner.connect(Target("127.0.0.1", int(port), user, password)).result(10)
deadline = time.monotonic() + 10
seat = runner.session.guardian
while seat is not None and seat.state.value in ("idle", "arming"):  # drive once it is armed (or refused)
    runner.sync()
    if time.monotonic() > deadline:
        break
def ui_thread():
    while True:  # what the window's 40 ms timer does: renew the lease, beat for the guardian
        runner.lease.renew()
        runner.ui_heartbeat()
        time.sleep(0.04)
threading.Thread(target=ui_thread, daemon=True).start()
if drive == "1":
    runner.lease.grant(DriveRatios(50.0, 0.0, 50.0))
print("ready", (seat.guardian.pid or 0) if seat is not None else 0, flush=True)
if sys.stdin.readline().strip() == "close":
    runner.close()
    print("closed", flush=True)
"""


sim = simulator(seed=1, users=(f"alice {PASSWORD} all",))


class Parent:
    """The driving process; ``guardian_pid`` is its guardian's (0 without one)."""

    def __init__(self, sim: SimThread, *, guardian: bool = True, drive: bool = True) -> None:
        self.sim = sim
        self.proc = subprocess.Popen(
            [sys.executable, "-c", PARENT],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(f"{sim.port} alice {PASSWORD} {int(guardian)} {int(drive)}\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline().split()
        assert line and line[0] == "ready", line
        self.guardian_pid = int(line[1])

    def close_cleanly(self) -> None:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write("close\n")
        self.proc.stdin.flush()
        assert self.proc.stdout.readline().strip() == "closed"
        assert self.proc.wait(10) == 0

    def end(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGCONT)
            self.proc.kill()
        self.proc.wait(10)
        if self.guardian_pid:
            eventually(lambda: not _alive(self.guardian_pid), timeout=10)


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def stops_by(sim: SimThread, identifier: str) -> int:
    return sum(1 for _t, _ident, who in sim.call(lambda: list(sim.server.stop_log)) if who == identifier)


def watchdog_stops(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.watchdog_stops))


def driving(sim: SimThread) -> bool:
    return abs(sim.snapshot().vel) > 1.0


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_killed_or_frozen_parent_is_stopped_by_its_guardian_not_the_watchdog(
    sim: SimThread, signum: int
) -> None:
    parent = Parent(sim)
    try:
        assert parent.guardian_pid, "no guardian was started"
        eventually(lambda: driving(sim), timeout=5)
        watchdog = watchdog_stops(sim)
        os.kill(parent.proc.pid, signum)
        eventually(lambda: stops_by(sim, IDENTIFIER) == 1, timeout=5)
        assert sim.call(lambda: sim.server.robot.mode_name) == "stop"
        assert watchdog_stops(sim) == watchdog, "the server's watchdog had to stop the robot"
    finally:
        parent.end()


def test_without_a_guardian_only_the_watchdog_stops_a_frozen_parent(sim: SimThread) -> None:
    """The baseline the guardian improves on (and proof the test above can fail)."""
    parent = Parent(sim, guardian=False)
    try:
        eventually(lambda: driving(sim), timeout=5)
        watchdog = watchdog_stops(sim)
        os.kill(parent.proc.pid, signal.SIGSTOP)
        eventually(lambda: watchdog_stops(sim) == watchdog + 1, timeout=5)
        assert stops_by(sim, IDENTIFIER) == 0
    finally:
        parent.end()


def test_a_clean_exit_while_driving_stops_by_the_parent_and_never_by_the_guardian(sim: SimThread) -> None:
    parent = Parent(sim)
    try:
        eventually(lambda: driving(sim), timeout=5)
        parent.close_cleanly()
        eventually(lambda: not _alive(parent.guardian_pid), timeout=10)
        assert sim.call(lambda: sim.server.robot.mode_name) == "stop"
        assert stops_by(sim, "") == 1, "the parent's own stop"
        assert stops_by(sim, IDENTIFIER) == 0
    finally:
        parent.end()


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_disarmed_guardian_never_stops(sim: SimThread, signum: int) -> None:
    """Connected but not driving: killing or freezing the parent must not reset the server's mode."""
    parent = Parent(sim, drive=False)
    try:
        assert parent.guardian_pid
        os.kill(parent.proc.pid, signum)
        if signum == signal.SIGKILL:
            eventually(lambda: not _alive(parent.guardian_pid), timeout=10)
        else:
            time.sleep(1.0)  # the point is that time passes with the parent frozen
        assert sim.call(lambda: list(sim.server.stop_log)) == []
    finally:
        parent.end()


def test_the_password_reaches_the_guardian_only_through_its_pipe(sim: SimThread) -> None:
    parent = Parent(sim, drive=False)
    try:
        pid = parent.guardian_pid
        assert pid
        cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
        environ = Path(f"/proc/{pid}/environ").read_bytes()
        assert b"guardian" in cmdline  # we are looking at the right process
        assert PASSWORD.encode() not in cmdline
        assert PASSWORD.encode() not in environ
        # …and it did log in with it: the simulator has two sessions as alice.
        assert len(sim.call(lambda: list(sim.server.sessions))) == 2
    finally:
        parent.end()


def test_a_refused_second_login_is_said_plainly_and_driving_still_works() -> None:
    notices: list[tuple[str, str]] = []
    with SimThread(SimConfig(port=0, seed=1, max_clients=1)) as sim:
        runner = ClientRunner(config=SessionConfig(fetch_map=False, guardian=True))
        runner.on_notice = lambda notice: notices.append((notice.level.value, notice.text))
        with runner:
            runner.connect(Target("127.0.0.1", sim.port)).result(10)

            def told() -> bool:
                runner.sync()
                return any("Guardian not available" in text for _level, text in notices)

            eventually(told, timeout=10)
            assert runner.session is not None and runner.session.guardian is not None
            assert runner.session.guardian.state is SeatState.UNAVAILABLE
            runner.lease.grant(DriveRatios(50.0, 0.0, 50.0))
            eventually(lambda: (runner.lease.renew(), driving(sim))[1], timeout=5)
            runner.stop()
            eventually(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", timeout=5)
    level, text = next(n for n in notices if "Guardian" in n[1])
    assert level == "warning"
    assert "maximum number" in text or "refus" in text.lower(), text


def test_the_guardian_can_only_send_zero_ratios_and_stop() -> None:
    """Structural: every request in the guardian package is in halt.py, of a constant or a literal;
    its only socket writes (login.py) hand over what the codec queued."""
    assert RatioDrive.decode(ZERO_RATIO_DRIVE) == RatioDrive(0.0, 0.0, 0.0)
    assert not RatioDrive.decode(ZERO_RATIO_DRIVE).moving
    assert SelfIdentifier.decode(IDENTIFIER_ARGS).identifier == IDENTIFIER
    requests: list[tuple[str, tuple[str, ...]]] = []
    socket_sends: list[tuple[str, str, tuple[str, ...]]] = []
    for path in sorted(GUARDIAN_DIR.glob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
                continue
            args = tuple(ast.unparse(a) for a in node.args)
            if node.func.attr in ("request", "request_once", "request_reply", "request_stop"):
                requests.append((path.name, args))
            elif node.func.attr in ("send", "sendall", "sendto", "sendmsg"):
                socket_sends.append((path.name, ast.unparse(node.func.value), args))
    assert requests, "found no requests: the check itself is broken"
    allowed = {
        ("halt.py", ("'ratioDrive'", "ZERO_RATIO_DRIVE")),
        ("halt.py", ("'stop'",)),
        ("halt.py", ("'identSetSelfIdentifier'", "IDENTIFIER_ARGS")),
    }
    assert set(requests) <= allowed, requests
    # The socket gets only the codec's queue (``_out``, filled from ``conn.data_to_send()`` alone).
    assert set(socket_sends) == {("login.py", "self.sock", ("self._out",))}, socket_sends
    login_source = (GUARDIAN_DIR / "login.py").read_text()
    assert login_source.count("self._out +=") == 1 and "self._out += self.conn.data_to_send()" in login_source
    # The Halter offers nothing but halt (and flush/connected): no way to reach the connection.
    public = {n for n in dir(halt.Halter) if not n.startswith("_")}
    assert public == {"halt", "flush", "connected"}


HEAVY = ("rtmu.client", "rtmu.recorder", "rtmu.ui", "gi", "asyncio")


def _guardian_modules() -> set[str]:
    code = "import sys, rtmu.guardian.child, rtmu.guardian.login; print(*sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    return set(out.stdout.split())


def test_the_guardian_process_imports_no_client_gtk_recorder_or_asyncio() -> None:
    """Its stop must not depend on the code it guards against, and it must start light."""
    loaded = _guardian_modules()
    heavy = sorted(m for m in loaded if any(m == h or m.startswith(h + ".") for h in HEAVY))
    assert heavy == [], heavy
    assert "rtmu.protocol.client_connection" in loaded  # it did load what it uses: the check can see


def test_the_guardian_process_does_not_import_numpy() -> None:
    assert "numpy" not in _guardian_modules()


def _rtmu_drive(sim: SimThread, pwfile: Path) -> subprocess.Popen[str]:
    argv = [sys.executable, "-m", "rtmu", "drive", f"127.0.0.1:{sim.port}", "--user", "alice"]
    argv += ["--password-file", str(pwfile), "--trans", "50", "--throttle", "50", "--seconds", "30"]
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_a_killed_rtmu_drive_is_stopped_by_its_guardian(sim: SimThread, tmp_path: Path) -> None:
    pwfile = tmp_path / "pw"
    pwfile.write_text(PASSWORD + "\n")
    proc = _rtmu_drive(sim, pwfile)
    try:
        eventually(lambda: driving(sim), timeout=15)
        watchdog = watchdog_stops(sim)
        proc.kill()
        eventually(lambda: stops_by(sim, IDENTIFIER) == 1, timeout=5)
        assert watchdog_stops(sim) == watchdog
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait(10)


def test_rtmu_drive_warns_in_one_line_when_the_guardian_is_refused_and_drives(tmp_path: Path) -> None:
    with SimThread(SimConfig(port=0, seed=1, max_clients=1)) as sim:
        argv = [sys.executable, "-m", "rtmu", "drive", f"127.0.0.1:{sim.port}", "--trans", "50"]
        done = subprocess.run([*argv, "--seconds", "0.5"], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        warnings = [line for line in done.stderr.splitlines() if "guardian not available" in line]
        assert len(warnings) == 1 and warnings[0].startswith("rtmu drive: warning:"), done.stderr
        assert sim.call(lambda: sim.server.robot.ratio_drives_received) > 0


def _beats(watch: Watch, kind: bytes, start: float, seconds: float, every: float) -> float:
    t = start
    for _ in range(round(seconds / every)):
        t += every
        watch.take(kind, t)
    return t


def test_the_guardian_learns_how_late_a_busy_parents_beats_come_within_its_bounds() -> None:
    """Its silent limit follows the link rule (base.link_timing): 0.4 s for a calm parent, more
    for one whose beats a busy machine delays now and then — never more than SILENT_CEILING."""
    watch = Watch(os.getpid(), learned_limit)  # this process: running, never "stopped"
    watch.take(m.ARM, 0.0)
    t = _beats(watch, m.BEAT_NET, 0.0, 300.0, 0.04)
    assert watch.limit(m.BEAT_NET, t) == pytest.approx(SILENT_LATE_NETWORK)
    assert watch.why_stop(t + 0.49) is None
    assert "network thread of the process driving the robot for 510 ms" in (watch.why_stop(t + 0.51) or "")
    watch.take(m.BEAT_NET, t + 0.35)  # a busy machine delayed one beat 350 ms…
    t = _beats(watch, m.BEAT_NET, t + 0.35, 5.0, 0.04)
    assert watch.why_stop(t + 0.6) is None  # …so a 600 ms silence is no alarm now
    assert SILENT_LATE < watch.limit(m.BEAT_NET, t) <= SILENT_CEILING
    assert watch.why_stop(t + SILENT_CEILING + 0.01) is not None  # but never beyond the ceiling
    watch.take(m.DISARM, t)
    assert watch.why_stop(t + 10.0) is None  # disarmed: nothing to watch


def test_the_network_thread_may_be_as_late_as_its_own_stale_limit_the_ui_thread_as_its_lease() -> None:
    """Measured cause of a false stop (bench_links, load 9–13): the guardian stopped a drive after
    419 ms without a network beat, under the 0.45 s its parent gives the status stream before it
    stops by itself. The network thread's floor is the promise (0.5 s); the UI thread's stays 0.4 s
    (its lease lapses at 0.3 s), and both still stop past their limits."""
    for source, other, floor in (
        (m.BEAT_NET, m.BEAT_UI, SILENT_LATE_NETWORK),
        (m.BEAT_UI, m.BEAT_NET, SILENT_LATE),
    ):
        watch = Watch(os.getpid(), learned_limit)
        watch.take(m.ARM, 0.0)
        for i in range(1, 7500):  # 300 s of both threads beating every 40 ms
            watch.take(m.BEAT_NET, i * 0.04)
            watch.take(m.BEAT_UI, i * 0.04)
        t = 7499 * 0.04
        assert watch.limit(source, t) == pytest.approx(floor)
        watch.take(other, t + floor + 0.01)  # the other thread goes on beating; this one is silent
        assert watch.why_stop(t + floor - 0.01) is None
        assert watch.why_stop(t + floor + 0.01) is not None
    assert SILENT_LATE < 0.45 < SILENT_LATE_NETWORK <= 0.5  # (the status ceiling sits between them)


def test_an_armed_guardian_sleeps_until_a_beat_is_late_then_looks_every_20_ms() -> None:
    """Between beats that come every 40 ms nothing but the pipe can call for a stop, so the armed loop
    sleeps until the oldest beat is QUICK_LATE late (it looked every 20 ms: 75 wake-ups a second while
    a window drove, 25 of them beats); from then on every CHECK_PERIOD, as before, until a limit says
    stop. Never later than any look that could find a reason to stop."""
    watch = Watch(os.getpid(), learned_limit)
    watch.take(m.ARM, 0.0)
    t = _beats(watch, m.BEAT_NET, 0.0, 10.0, 0.04)
    t = _beats(watch, m.BEAT_UI, t - 0.04, 0.04, 0.04)  # both sources beat; the UI's last came last
    oldest = min(watch.last.values())
    assert watch.next_look(oldest + 0.01) == pytest.approx(QUICK_LATE - 0.01)
    assert watch.next_look(oldest + QUICK_LATE + 0.001) == CHECK_PERIOD
    for now in (oldest + step / 1000 for step in range(0, int(QUICK_LATE * 1000))):
        assert watch.why_stop(now) is None  # nothing it slept through could have stopped
    short = Watch(os.getpid(), lambda _source: FixedLimit(QUICK_LATE / 2))  # a limit below QUICK_LATE:
    short.take(m.ARM, 0.0)
    short.take(m.BEAT_NET, 0.0)
    assert short.next_look(0.001) == CHECK_PERIOD  # the old way, every 20 ms


def test_the_guardians_reasons_name_no_window_it_may_not_have() -> None:
    """rtmu drive and rtmu bridge have guardians too: their stop reasons speak of the driving process."""
    import os

    from rtmu.guardian import messages as m
    from rtmu.guardian.child import Watch

    watch = Watch(os.getpid())
    watch.take(m.BEAT_NET, 0.0)
    watch.take(m.ARM, 0.0)
    late = watch.why_stop(10.0)
    watch.eof = True
    gone = watch.why_stop(10.0)
    for reason in (late, gone):
        assert reason is not None and "window" not in reason and "process driving the robot" in reason


def test_a_stopped_parent_is_looked_for_once_a_beat_is_20_ms_late() -> None:
    """bench_safety: a SIGSTOPped window drove on 85 ms (p50) while the guardian waited for a beat
    0.1 s late before it looked in /proc. Beats come every 40 ms: 60 ms is enough to look, and a
    running parent is never found stopped however late its beats (the silent limits judge it)."""
    parent = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        watch = Watch(parent.pid, learned_limit)
        watch.take(m.ARM, 0.0)
        watch.take(m.BEAT_NET, 0.0)
        watch.take(m.BEAT_UI, 0.0)
        assert watch.why_stop(0.07) is None  # running: late, not stopped
        parent.send_signal(signal.SIGSTOP)
        eventually(lambda: parent_frozen(parent.pid), timeout=10)
        assert "stopped or gone" in (watch.why_stop(0.07) or "")
        assert watch.why_stop(0.05) is None  # not yet late: no look
    finally:
        parent.send_signal(signal.SIGCONT)
        parent.kill()
        parent.wait(10)
