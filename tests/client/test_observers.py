"""Observers never command: every looking subcommand, during a navigation, on every exit path.

Two real simulators — an LD ``aram`` one (routes, say, LD docking) and an ARIA one (a camera, a
camera head, ArConfig, which 6MTX robots do not list) — each navigate their robot between two far
goals, driven by an operator connection of this test. Each observer subcommand runs as its own
process through its own fault proxy (so the simulator's per-connection request log,
``SimServer.heard``, tells whose requests are whose) against the one that offers what it looks at,
and ends by itself (with the code that says it did its work), by SIGINT, SIGTERM or SIGHUP, or by a
lost link (never with 0). Afterwards the simulators must have heard no motion request
(``rtmu.protocol.motion``) from any of them: only the operator commanded. Commands that would finish
at once are held mid-command by the proxy (the server's answers are held after their first request)
so that a signal or a lost link finds them connected. Every code is one the command's help lists.
"""

from __future__ import annotations

import asyncio
import importlib
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from linkfaults import TO_CLIENT, TO_SERVER, Direction, FaultProxy
from patience import cli_timeout
from rtmu.base import exit_codes
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE, EXIT_WHY_NAVIGATING
from rtmu.cli import build_parser, main
from rtmu.client.connection import AriaClient
from rtmu.client.errors import MotionRefused
from rtmu.client.roles import Role
from rtmu.protocol.commands import FIRST_DATA_NUMBER, ClientCommand
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.motion import MOTION_REQUESTS
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.navigation import GotoGoal
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target
from simulators import running

from .navsim import OFFICE
from .servers import SPECS, ServerThread, TestServer
from .uiqueue import eventually

GOALS = ("Corridor End", "Room 101")
"""Far apart on the office map: the robot is always on its way to one of them."""
ENDING = {"sigint": signal.SIGINT, "sigterm": signal.SIGTERM, "sighup": signal.SIGHUP}


DONE = frozenset({EXIT_OK})
DURING_NAVIGATION = frozenset({EXIT_OK, EXIT_WHY_NAVIGATING})
"""``why`` (and doctor's last step) during a navigation: 28, or 0 at a goal between two legs."""
DOCTOR_STEPS = frozenset(range(exit_codes.EXIT_DOCTOR_RESOLVE, exit_codes.EXIT_DOCTOR_STATUS + 1))
"""A doctor names the step at which the link went."""


@dataclass(frozen=True)
class Observer:
    name: str
    ends: tuple[str, ...]
    """A command line that ends by itself ({addr}, {tmp} filled in)."""
    runs: tuple[str, ...] | None = None
    """One that runs until ended (None: ``ends``, held by the proxy after its first request)."""
    holds_at_login: bool = False
    """It sends no request at all (``probe`` reads the data list): held after its INTRODUCTION."""
    sim: str = "aram"
    """The simulator that offers what it looks at: ``aram`` or ``aria`` (a camera, ArConfig)."""
    ended: frozenset[int] = DONE
    """The codes it ends with by itself during a navigation: it did its work (not 4, not offered)."""
    waits: bool = True
    """It waits for the server's answers (False: ``say`` sends its one command and is done), so a link
    lost while it runs is never reported as done…"""
    lost: frozenset[int] = frozenset({EXIT_CONNECTION})
    """…but with these codes."""

    @property
    def held(self) -> bool:
        return self.runs is None


OBSERVERS = (
    Observer("status", ("status", "{addr}", "--count", "3"), ("status", "{addr}")),
    Observer("watch", ("watch", "{addr}", "--seconds", "1"), ("watch", "{addr}")),
    Observer(
        "video",
        ("video", "{addr}", "--seconds", "3", "--out", "{tmp}/frames"),
        ("video", "{addr}", "--seconds", "300"),
        sim="aria",
    ),
    Observer(
        "record",
        ("record", "{addr}", "--out", "{tmp}/r.mcap", "--seconds", "1.5"),
        ("record", "{addr}", "--out", "{tmp}/r.mcap"),
    ),
    Observer(
        "bridge",
        ("bridge", "{addr}", "--foxglove", "--ws-port", "0", "--seconds", "1.5"),
        ("bridge", "{addr}", "--foxglove", "--ws-port", "0"),
    ),
    Observer("probe", ("probe", "{addr}"), holds_at_login=True),
    Observer("image", ("image", "{addr}", "--out", "{tmp}/p.jpg"), sim="aria"),
    Observer("drawings", ("drawings", "{addr}")),
    Observer("map", ("map", "{addr}", "--out", "{tmp}/m.map")),
    Observer("ptz", ("ptz", "{addr}", "--json"), sim="aria"),
    Observer("goals", ("goals", "{addr}")),
    Observer("routes", ("routes", "{addr}")),
    Observer("commands", ("commands", "{addr}")),
    Observer("config", ("config", "{addr}"), sim="aria"),
    # say sends its one command and ends without waiting for an answer, so a signal sent "while it
    # runs" could land as it exits (a loaded machine: killed by SIGINT during interpreter shutdown,
    # -2). Held at its login instead, it is surely mid-command when the signal or the cut comes.
    Observer("say", ("say", "{addr}", "hello"), holds_at_login=True, waits=False),
    Observer("doctor", ("doctor", "{addr}"), ended=DURING_NAVIGATION, lost=DOCTOR_STEPS),
    Observer("files", ("files", "{addr}", "ls")),
    Observer("scan", ("scan", "{addr}", "status")),
    # Re-reading an unchanged map file changes nothing; no mapUpdated comes, so it waits (its timeout
    # with the suite's patience: it bounds the login too, which a loaded machine ran past 3 s).
    Observer(
        "mapedit",
        ("mapedit", "{addr}", "--check-map", "--timeout", cli_timeout(3)),
        ("mapedit", "{addr}", "--check-map"),
    ),
    Observer("why", ("why", "{addr}"), ended=DURING_NAVIGATION),
    Observer(
        "call", ("call", "{addr}", "updateNumbers"), ("call", "{addr}", "updateNumbers", "--every", "100")
    ),
)
"""Each against the simulator that offers everything it looks at (routes, say, dock … or a camera)."""
OPERATORS = {"drive", "goto", "home", "dock", "localize", "patrol", "run"}
"""Subcommands that may command motion (a test of their own stops lives in tests/cli/test_nav_cli.py)."""
OPERATOR_WITH = {"why": "--fix", "call": "--yes"}
"""Observers that become operators only with this option (a fix may send stop; a confirmed call may
be a motion request): the option is the operator's explicit yes."""
OFFLINE = {"decode", "mapinfo", "sim", "replay"}
"""Subcommands that reach no robot server (replay's own rule: tests/client/test_replay_session.py)."""


def test_every_subcommand_is_an_observer_an_operator_or_offline() -> None:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "subcommand")
    names = set(sub.choices)  # type: ignore[attr-defined]
    observers = {o.name for o in OBSERVERS} | {"fleet"}
    assert names == observers | OPERATORS | OFFLINE, "say whether a new subcommand commands motion"
    assert not observers & OPERATORS
    assert set(OPERATOR_WITH) <= observers, "observers unless the option is given"
    for name, option in OPERATOR_WITH.items():
        assert any(option in a.option_strings for a in sub.choices[name]._actions), (name, option)  # type: ignore[attr-defined]


class Navigation:
    """An operator connection of the test that keeps the robot navigating (its own loop and thread)."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.sent = 0
        self._stop = threading.Event()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._run()), daemon=True)

    async def _run(self) -> None:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", self.port), timeout=10, role=Role.OPERATOR)
        self._ready.set()
        goal = 0
        try:
            while not self._stop.is_set():
                status = (await client.request_once("updateStrings", timeout=10)).decode()
                if not str(getattr(status, "status", "")).startswith("Going to"):
                    client.send(GotoGoal(GOALS[goal]))
                    self.sent += 1
                    goal = 1 - goal
                await asyncio.sleep(0.3)
        finally:
            await client.disconnect()

    def __enter__(self) -> Navigation:
        self._thread.start()
        assert self._ready.wait(20), "the operator could not connect"
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(20)


@pytest.fixture(scope="module")
def navigating() -> Iterator[dict[str, SimThread]]:
    with (
        running(map_path=OFFICE, seed=3, profile="aram") as aram,
        running(map_path=OFFICE, seed=3) as aria,
        Navigation(aram.port) as nav_aram,
        Navigation(aria.port) as nav_aria,
    ):
        sims = {"aram": aram, "aria": aria}
        for sim in sims.values():
            eventually(lambda sim=sim: sim.snapshot().status.startswith("Going to"), timeout=30)  # type: ignore[misc]
        yield sims
        assert nav_aram.sent >= 1 and nav_aria.sent >= 1
        for kind, sim in sims.items():
            assert sim.snapshot().status.startswith(("Going to", "Arrived at")), f"something stopped {kind}"


def hold_after_first_request(proxy: FaultProxy, *, at_login: bool) -> None:
    """Hold the server's answers from the client's first data request (or its login) on: it waits."""
    decoder = PacketDecoder()
    first = ClientCommand.INTRODUCTION if at_login else FIRST_DATA_NUMBER

    def tap(direction: Direction, data: bytes) -> None:
        if direction != TO_SERVER or TO_CLIENT in proxy.muted:
            return
        if any(p.command >= first for p in decoder.feed(data)):
            proxy.mute(TO_CLIENT)

    proxy.tap = tap


@dataclass
class Run:
    observer: Observer
    proxy: FaultProxy
    process: subprocess.Popen[str]
    signalled: bool = False
    cut: bool = False
    """Its link was cut while it ran."""

    def peers(self) -> set[str]:
        return {f"127.0.0.1:{port}" for port in self.proxy.server_ports}


def start(observer: Observer, port: int, tmp: Path, *, running: bool) -> Run:
    """``rtmu OBSERVER`` through a proxy of its own to the server on ``port``."""
    proxy = FaultProxy("127.0.0.1", port).start()
    argv = observer.runs if running and observer.runs is not None else observer.ends
    if running and observer.held:
        hold_after_first_request(proxy, at_login=observer.holds_at_login)
    where = tmp / observer.name
    where.mkdir(exist_ok=True)
    args = [a.format(addr=f"127.0.0.1:{proxy.port}", tmp=where) for a in argv]
    timeout = [] if "--timeout" in args else ["--timeout", cli_timeout(30)]
    process = subprocess.Popen(
        [sys.executable, "-m", "rtmu", *args, *timeout],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    return Run(observer, proxy, process)


def heard_from(sim: SimThread, run: Run) -> list[str]:
    peers = run.peers()
    assert sim.server is not None
    heard = sim.call(sim.server.heard.all)
    return [h.name for h in heard if h.peer in peers]


def wait_connected(sim: SimThread, runs: list[Run], timeout: float = 90.0) -> None:
    """Until each command has sent a request (it is logged in and at work), is held, or has ended."""
    deadline = time.monotonic() + timeout
    for run in runs:
        while run.process.poll() is None and not heard_from(sim, run) and TO_CLIENT not in run.proxy.muted:
            assert time.monotonic() < deadline, f"rtmu {run.observer.name} never reached the server"
            time.sleep(0.05)


def finish(runs: list[Run], timeout: float = 90.0) -> dict[str, tuple[int, str]]:
    ended: dict[str, tuple[int, str]] = {}
    for run in runs:
        try:
            _out, err = run.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            run.process.kill()
            _out, err = run.process.communicate()
            pytest.fail(f"rtmu {run.observer.name} did not end: {err}")
        finally:
            run.proxy.close()
        ended[run.observer.name] = (run.process.returncode, err)
    return ended


def assert_no_motion(sim: SimThread, runs: list[Run]) -> None:
    for run in runs:
        sent = heard_from(sim, run)
        assert run.proxy.connections, f"rtmu {run.observer.name} never connected: the test proves nothing"
        motion = [name for name in sent if name in MOTION_REQUESTS]
        assert not motion, f"rtmu {run.observer.name} (an observer) sent {motion}"


def declared(name: str) -> tuple[int, ...]:
    """The codes ``rtmu NAME --help`` lists (its module's ``EXITS``)."""
    module = importlib.import_module(f"rtmu.subcommands.{name}")
    return tuple(getattr(module, "EXITS", exit_codes.NETWORK))


@pytest.mark.parametrize("path", ["end", "sigint", "sigterm", "sighup", "lost link"])
def test_no_observer_sends_a_motion_request_during_a_navigation(
    navigating: dict[str, SimThread], tmp_path: Path, path: str
) -> None:
    running = path != "end"
    runs = [start(o, navigating[o.sim].port, tmp_path, running=running) for o in OBSERVERS]
    sim_of = {run.observer.name: navigating[run.observer.sim] for run in runs}
    try:
        for kind, sim in navigating.items():
            wait_connected(sim, [run for run in runs if run.observer.sim == kind])
        for run in runs:
            if path in ENDING and run.process.poll() is None:
                run.process.send_signal(ENDING[path])
                run.signalled = True
            elif path == "lost link":
                run.cut = run.process.poll() is None
                run.proxy.reset()
        if path == "lost link":  # a recorder or bridge reconnects and records on: end it once it has
            for run in runs:
                if run.observer.name in ("record", "bridge"):
                    eventually(lambda run=run: run.proxy.connections >= 2, timeout=60)  # type: ignore[misc]
                    time.sleep(0.5)
                    run.process.send_signal(signal.SIGINT)
                    run.signalled = True
        ended = finish(runs)
    finally:
        for run in runs:
            if run.process.poll() is None:
                run.process.kill()
            run.proxy.close()
    for run in runs:
        assert_no_motion(sim_of[run.observer.name], [run])
    for run in runs:
        name = run.observer.name
        code, err = ended[name]
        assert code >= 0, f"rtmu {name} was killed by a signal instead of ending: {err}"
        assert code in declared(name), f"rtmu {name} exited {code}, which its --help does not list: {err}"
        if path == "end":
            assert code in run.observer.ended, f"rtmu {name} did not do its work: {code} {err}"
        if path in ENDING and run.signalled:
            assert code == 128 + ENDING[path], (name, code, err)
        if path == "lost link" and run.signalled:
            assert code == 128 + signal.SIGINT, (name, code, err)
        elif path == "lost link" and run.cut and run.observer.waits:
            assert code in run.observer.lost, f"rtmu {name} lost its link and exited {code}: {err}"
    for sim in navigating.values():
        assert sim.snapshot().status.startswith(("Going to", "Arrived at"))


def test_the_console_never_sends_a_motion_request_without_yes_whatever_its_description() -> None:
    """A server may describe ``tourGoalsInList`` as a list of names: it is still a motion request."""
    specs = [
        *SPECS,
        ("tourGoalsInList", "the names it knows", "none", "string", "Navigation", "RETURN_SINGLE"),
    ]
    with ServerThread(TestServer(specs)) as server:
        where = f"127.0.0.1:{server.port}"
        assert main(["call", where, "tourGoalsInList", "--timeout", cli_timeout(5)]) == EXIT_USAGE
        assert main(["call", where, "stop", "--timeout", cli_timeout(5)]) == EXIT_USAGE
        assert (
            main(["call", where, "updateNumbers", "--timeout", cli_timeout(5)]) == EXIT_OK
        )  # a read needs no yes
        assert not [n for n in server.names() if n in MOTION_REQUESTS]
        assert (
            main(["call", where, "stop", "--yes", "--timeout", cli_timeout(5)]) == EXIT_OK
        )  # an operator now
        assert "stop" in server.names()


def test_a_lost_link_while_waiting_for_a_broadcast_is_a_connection_failure() -> None:
    """mapedit --check-map waits for mapUpdated: a lost link is 3, not "the file had not changed"."""
    specs = [*SPECS, ("checkMap", "re-read the map file", "none", "none", "Map", "RETURN_NONE")]
    server = TestServer(specs)

    def crash_on_check_map(side, args):  # type: ignore[no-untyped-def]
        server.kill(side)  # a server that goes away instead of re-reading its map
        return None

    server.handlers["checkMap"] = crash_on_check_map
    with ServerThread(server):
        code = main(["mapedit", f"127.0.0.1:{server.port}", "--check-map", "--timeout", cli_timeout(20)])
    assert code == EXIT_CONNECTION
    assert "checkMap" in server.names()


def test_an_observers_client_refuses_motion_before_the_wire() -> None:
    """The refusal is the client's own: nothing reaches the server, whatever the caller does."""
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:

        async def go() -> None:
            client = AriaClient()
            await client.connect(Target("127.0.0.1", sim.port), timeout=10, role=Role.OBSERVER)
            try:
                for attempt in (
                    lambda: client.send("stop"),
                    lambda: client.send(RatioDrive(0.0, 0.0, 0.0)),
                    lambda: client.send(GotoGoal("Room 101")),
                    lambda: client.request("ratioDrive", 100, lambda p: None),
                ):
                    with pytest.raises(MotionRefused):
                        attempt()
                await client.request_once("updateNumbers", timeout=10)  # the link still works
                assert not client.drove
            finally:
                await client.disconnect()

        asyncio.run(go())
        assert sim.server is not None
        heard = sim.call(sim.server.heard.all)
        assert "updateNumbers" in [h.name for h in heard]
        assert not [h.name for h in heard if h.name in MOTION_REQUESTS]


def test_an_operator_stops_only_its_own_drive_when_it_ends() -> None:
    """A session that never drove leaves a navigation alone when it disconnects; one that drove stops."""
    from rtmu.client.runner import ClientRunner
    from rtmu.client.session import SessionConfig

    with SimThread(SimConfig(port=0, map_path=OFFICE, seed=3)) as sim, Navigation(sim.port):
        assert sim.server is not None
        eventually(lambda: sim.snapshot().status.startswith("Going to"), timeout=30)
        with ClientRunner(config=SessionConfig(fetch_map=False)) as runner:
            runner.connect(Target("127.0.0.1", sim.port, auto_reconnect=False)).result(20)
            runner.sync()
        time.sleep(0.5)
        navigators = sim.call(lambda: sim.server.heard.sessions_that_sent(frozenset({"gotoGoal"})))  # type: ignore[union-attr]
        stoppers = sim.call(lambda: sim.server.heard.sessions_that_sent(frozenset({"stop"})))  # type: ignore[union-attr]
        assert stoppers <= navigators, "a window that never drove stopped somebody else's navigation"
        assert sim.snapshot().status.startswith(("Going to", "Arrived at"))


@pytest.mark.parametrize("path", ["end", "sigint", "sigterm", "sighup", "lost link"])
def test_fleet_commands_no_robot_behind_a_central_server(tmp_path: Path, path: str) -> None:
    """``rtmu fleet`` logs in to every robot a central server forwards: none hears a motion request."""
    from rtmu.sim.central_thread import CentralThread

    observer = Observer("fleet", ("fleet", "{addr}"))
    with CentralThread(robots=2) as fleet:
        run = start(observer, fleet.port, tmp_path, running=path != "end")
        try:
            if path != "end":
                eventually(lambda: TO_CLIENT in run.proxy.muted or run.process.poll() is not None, timeout=90)
                if path in ENDING:
                    run.process.send_signal(ENDING[path])
                else:
                    run.proxy.reset()
            code, err = finish([run])["fleet"]
        finally:
            if run.process.poll() is None:
                run.process.kill()
            run.proxy.close()
        heard = [h.name for server in fleet.sims.values() for h in fleet.call(server.heard.all)]
    if path == "end":
        assert code == 0, err
        assert "updateNumbers" in heard, "it never reached a robot: the test proves nothing"
    elif path in ENDING:
        assert code == 128 + ENDING[path], err
    else:
        assert code == 3, err
    assert not [name for name in heard if name in MOTION_REQUESTS]
