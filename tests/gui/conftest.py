"""GUI tests: one Xvfb for the session, the real app, the real simulator, real key events (xdotool).

The display is started when this file is loaded — before any test module
imports GTK — and ``DISPLAY``/``GSK_RENDERER=cairo`` are exported (the cairo
renderer gives the same pixels on every machine). A private D-Bus session bus
is started beside it (``DBUS_SESSION_BUS_ADDRESS``): the application registers
on it as on a desktop, and nothing reaches the developer's own session. Settings go to a temporary
``XDG_CONFIG_HOME``. Every test saves PNGs of the window into one folder,
printed at the start and at the end of the run.

No wait here is open-ended: ``pump`` and ``xdotool`` fail after a timeout, and
each app is shut down and its window destroyed after its test.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from linkfaults import FaultProxy
    from rtmu.sim import SimThread

    from .harness import Gui

REPO = Path(__file__).resolve().parents[2]
_XVFB = shutil.which("Xvfb")
_XDOTOOL = shutil.which("xdotool")
_DBUS_DAEMON = shutil.which("dbus-daemon")
_proc: subprocess.Popen[bytes] | None = None
SKIP_REASON = ""


def _spawn_xvfb(size: str) -> tuple[subprocess.Popen[bytes] | None, str | None]:
    """Start Xvfb with one screen of ``size`` (e.g. ``1280x1024``) on a free display: (process, ':N')."""
    proc, number = _spawn_telling(
        lambda fd: [
            _XVFB or "Xvfb",
            "-displayfd",
            str(fd),
            "-screen",
            "0",
            f"{size}x24",
            "-nolisten",
            "tcp",
            "-noreset",
        ]
    )
    return proc, None if number is None else f":{number}"


def _spawn_session_bus() -> str | None:
    """A private D-Bus session bus for this run: its address (``DBUS_SESSION_BUS_ADDRESS``), or None."""
    _, address = _spawn_telling(
        lambda fd: [_DBUS_DAEMON or "dbus-daemon", "--session", "--nofork", f"--print-address={fd}"]
    )
    return address


def _spawn_telling(argv: Callable[[int], list[str]]) -> tuple[subprocess.Popen[bytes] | None, str | None]:
    """Start a server that writes one line (its display number, its address) to the descriptor it is
    given when it is ready; (process, that line), or (None, None) when it said nothing within 15 s.
    It is ended when the test run ends. Never marked as the running test's own (``isolation.OWNER``):
    a session's screen first asked for inside a test (``request.getfixturevalue``) outlives that test,
    and was killed at its end as a leak, leaving the next tests of the worker a dead display."""
    from .isolation import OWNER

    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(
        argv(write_fd),
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={name: value for name, value in os.environ.items() if name != OWNER},
    )
    os.close(write_fd)
    deadline = time.monotonic() + 15
    data = b""
    os.set_blocking(read_fd, False)
    while time.monotonic() < deadline and not data.endswith(b"\n"):
        try:
            chunk = os.read(read_fd, 16)
        except BlockingIOError:
            time.sleep(0.02)
            if proc.poll() is not None:
                break
            continue
        if not chunk:
            break
        data += chunk
    os.close(read_fd)
    if not data.strip():
        _terminate(proc)
        return None, None
    atexit.register(_terminate, proc)
    return proc, data.strip().decode()


def _start_xvfb() -> str | None:
    """Start the session's Xvfb on a free display number; returns ':N' or None."""
    global _proc
    _proc, display = _spawn_xvfb("1280x1024")
    return display


def _terminate(proc: subprocess.Popen[bytes] | None) -> None:
    if proc is not None and proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()


def _stop_xvfb() -> None:
    global _proc
    proc, _proc = _proc, None
    _terminate(proc)


TMP_ROOT = tempfile.mkdtemp(prefix="rtmu-gui-")
"""Everything the GUI tests write besides screenshots (config, settings, stage pictures); removed at the
end of the session. The harness finds it through RTMU_GUI_TMP."""
os.environ["RTMU_GUI_TMP"] = TMP_ROOT

if _XVFB is None or _XDOTOOL is None:
    SKIP_REASON = "Xvfb and xdotool are needed for the GUI tests (apt-get install xvfb xdotool)"
elif _DBUS_DAEMON is None:
    SKIP_REASON = "dbus-daemon is needed for the GUI tests' session bus (apt-get install dbus)"
else:
    display = _start_xvfb()
    bus = _spawn_session_bus()
    if display is None or bus is None:
        SKIP_REASON = "Xvfb did not start" if display is None else "the D-Bus session bus did not start"
    else:
        os.environ["DBUS_SESSION_BUS_ADDRESS"] = bus
        os.environ["DISPLAY"] = display
        os.environ.pop("WAYLAND_DISPLAY", None)
        os.environ["GDK_BACKEND"] = "x11"
        os.environ["GSK_RENDERER"] = "cairo"
        os.environ["NO_AT_BRIDGE"] = "1"
        # GTK 4 ignores NO_AT_BRIDGE; without this it asks the session bus for an accessibility bus and,
        # when at-spi's launcher has gone (as on a busy CI machine), prints a Gtk-CRITICAL the tests would
        # rightly count as a failure. Accessibility tests start their own bus and turn it back on.
        os.environ["GTK_A11Y"] = "none"
        os.environ["GSETTINGS_BACKEND"] = "memory"
        os.environ["XDG_CONFIG_HOME"] = str(Path(TMP_ROOT) / "config")

SCREENSHOTS = Path(os.environ["RTMU_SCREENSHOTS"])
"""The run's one screenshot folder (named in ``tests/conftest.py``, which also reports and removes it)."""


def pytest_report_header(config: pytest.Config) -> list[str]:
    if SKIP_REASON:
        return [f"rtmu gui: {'failing, CI=true' if CI else 'skipped'} ({SKIP_REASON})"]
    return [f"rtmu gui: Xvfb on {os.environ.get('DISPLAY')}, screenshots in {SCREENSHOTS}"]


CI = os.environ.get("CI", "").lower() in ("true", "1")
"""On CI a machine without Xvfb/xdotool is a broken set-up: the GUI tests fail instead of skipping,
so a green run always means the window was tested."""


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    here = Path(__file__).parent
    for item in items:
        if here in Path(str(item.fspath)).parents:
            item.add_marker(pytest.mark.gui)
            if SKIP_REASON and not CI:
                item.add_marker(pytest.mark.skip(reason=SKIP_REASON))


def pytest_runtest_setup(item: pytest.Item) -> None:
    if SKIP_REASON and CI and item.get_closest_marker("gui"):
        pytest.fail(f"CI=true but the GUI cannot be tested: {SKIP_REASON}", pytrace=False)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Leave only the screenshot folder behind (``tests/conftest.py`` removes it too when it is empty)."""
    shutil.rmtree(TMP_ROOT, ignore_errors=True)


@pytest.fixture(scope="session")
def screenshots() -> Path:
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    return SCREENSHOTS


@contextlib.contextmanager
def screen_of(size: str) -> Iterator[str]:
    """An X server of its own whose only screen is ``size`` (e.g. ``360x720``): ':N', ended after."""
    proc, display = _spawn_xvfb(size)
    if display is None:
        pytest.fail(f"an Xvfb of {size} did not start")
    try:
        yield display
    finally:
        _terminate(proc)


@pytest.fixture(scope="session")
def phone_screen() -> Iterator[str]:
    """An X server whose only screen is a 360×720 portrait phone: ':N'."""
    with screen_of("360x720") as display:
        yield display


@pytest.fixture(scope="session")
def laptop_screen() -> Iterator[str]:
    """An X server whose only screen is a 1280×800 laptop (640×400 at ``GDK_SCALE=2``): ':N'. (Once this
    process has had a window there, a window of another process there never got the keyboard — seen,
    not yet explained: a test that starts another process on it runs first.)"""
    with screen_of("1280x800") as display:
        yield display


@pytest.fixture(scope="session")
def small_screen() -> Iterator[str]:
    """A second X server whose only screen is 800×480 (the smallest the window is made for): ':N'."""
    proc, display = _spawn_xvfb("800x480")
    if display is None:
        pytest.fail("a second Xvfb (800x480) did not start")
    try:
        yield display
    finally:
        _terminate(proc)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]):  # type: ignore[no-untyped-def]
    report = yield
    if report.when == "call":
        item.stash[_CALL_PASSED] = report.passed
    return report


_CALL_PASSED = pytest.StashKey[bool]()


@pytest.fixture(autouse=True)
def every_window_test_saves_a_picture(request: pytest.FixtureRequest) -> Iterator[None]:
    """A passing test that opened the window and saved no PNG fails: each state it checks is also seen."""
    from .harness import COUNTS

    before = dict(COUNTS)
    yield
    opened = COUNTS["windows"] > before["windows"]
    passed = request.node.stash.get(_CALL_PASSED, False)
    if opened and passed and COUNTS["pictures"] == before["pictures"]:
        pytest.fail("this test opened the window but saved no screenshot (gui.shot or gui.render)")


_OWNER_COUNT = [0]


@pytest.fixture(autouse=True)
def every_test_leaves_a_clean_x_server_and_no_processes(request: pytest.FixtureRequest) -> Iterator[None]:
    """Reset what a test may leave behind, whether it passed, failed or timed out: the apps it left
    open are closed, every window still on screen destroyed, held keys and mouse buttons released,
    and every process it started (marked through the environment, see ``isolation``) ends. A passing
    test that leaked a process or left a window on screen fails: each test owns and removes what it
    starts."""
    from . import isolation
    from .harness import OPEN

    _OWNER_COUNT[0] += 1
    mark = f"{os.getpid()}.{_OWNER_COUNT[0]}"
    previous = os.environ.get(isolation.OWNER)
    os.environ[isolation.OWNER] = mark
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop(isolation.OWNER, None)
        else:
            os.environ[isolation.OWNER] = previous
        left_open = isolation.close_all(OPEN)
        left_shown = isolation.destroy_windows()
        if not SKIP_REASON:
            isolation.release_input()
        killed = isolation.end_processes(mark)
        isolation.reap_children()
    if request.node.stash.get(_CALL_PASSED, False) and (killed or left_open or left_shown):
        pytest.fail(
            f"this test left {left_open} app(s) open, windows on screen {left_shown} and "
            f"{len(killed)} process(es) running: {killed}",
            pytrace=False,
        )


@pytest.fixture
def gui(request: pytest.FixtureRequest, screenshots: Path, sim: SimThread) -> Iterator[Gui]:
    """The real window connected to the module's ``sim`` fixture (each module picks its simulator)."""
    from .harness import Gui  # imports GTK: only once the display is set up

    g = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
    try:
        yield g
    finally:
        g.close()


@pytest.fixture
def faulty_link(
    request: pytest.FixtureRequest, screenshots: Path
) -> Iterator[tuple[Gui, SimThread, FaultProxy]]:
    """(window, simulator, proxy): the window connected to the office simulator through a
    :class:`~linkfaults.FaultProxy` whose faults the test switches; Up is released at the end."""
    from linkfaults import FaultProxy
    from simulators import running

    from .harness import OFFICE_MAP, Gui

    with running(map_path=OFFICE_MAP, seed=1) as sim, FaultProxy("127.0.0.1", sim.port) as proxy:
        g = Gui.start(screenshots, request.node.name, "127.0.0.1", proxy.port)
        try:
            yield g, sim, proxy
        finally:
            g.xdotool("keyup", "Up")
            g.close()


@pytest.fixture(scope="module")
def office() -> object:
    """The bundled office map, read (for frames drawn without a window: ``office_frames``)."""
    from rtmu.mapfile.reader import read_map
    from rtmu.package_data import project_map

    return read_map(project_map("office.map"))


@pytest.fixture()
def tiles(office: object) -> Iterator[object]:
    """A tile cache of the office map with its index built (tiles render on its own thread)."""
    from rtmu.ui.tiles import TileCache

    cache = TileCache(lambda: None)
    cache.set_map(office.points, office.segments)  # type: ignore[attr-defined]
    assert cache.wait_idle(30), "the tile worker never finished the index"
    yield cache
    cache.close()
