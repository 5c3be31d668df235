"""Drive the real RTMU window in-process: pump its main loop, press real keys, take screenshots.

The test thread *is* the GTK thread: :meth:`Gui.pump` iterates the default
main context until a condition holds or a timeout fails the test, so nothing
here can hang. Keys go through the X server with xdotool (started without
waiting; the loop keeps running while it types).
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import gi
import numpy as np

from rtmu.package_data import project_map

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
gi.require_version("GdkX11", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import Gdk, GdkX11, GLib, Graphene, Gtk  # noqa: E402
from PIL import Image  # noqa: E402

from rtmu.fleet.sessions import RobotSession  # noqa: E402
from rtmu.model.observables import OperatorState, Phase, RobotModel  # noqa: E402
from rtmu.package_data import APP_ID  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402
from rtmu.ui.window import MainWindow  # noqa: E402

from .process import PATIENCE, screenshot  # noqa: E402

OFFICE_MAP = project_map("office.map")
COUNTS = {"windows": 0, "pictures": 0}
"""Windows opened and pictures saved so far: every test that opens a window must leave a picture."""
OPEN: dict[int, Callable[[], None]] = {}
"""The teardown of every app still open, by id: the GUI conftest closes what a failed test left."""


@contextlib.contextmanager
def on_display(name: str) -> Iterator[Gdk.Display]:
    """Open the X display ``name`` and make it GTK's default (and ``DISPLAY`` for xdotool) meanwhile."""
    manager = Gdk.DisplayManager.get()
    before = manager.get_default_display()
    env_before = os.environ.get("DISPLAY")
    display = manager.open_display(name)
    assert display is not None, f"cannot open {name}"
    manager.set_default_display(display)
    os.environ["DISPLAY"] = name
    try:
        yield display
    finally:
        manager.set_default_display(before)
        if env_before is None:
            os.environ.pop("DISPLAY", None)
        else:
            os.environ["DISPLAY"] = env_before
        display.close()


def register(app: RtmuApplication) -> None:
    """Register ``app`` on the run's session bus under an id of its own (``io.github.rtmu.Rtmu.TestN``).

    This process opens many apps one after the other (``rtmu`` opens one): GLib keeps a closed app's
    object exported on the bus until the app is finalized, so a second app with the same id could not
    register here. Apps started as processes keep the real id."""
    _REGISTERED[0] += 1
    app.set_application_id(f"{APP_ID}.Test{_REGISTERED[0]}")
    app.register(None)


_REGISTERED = [0]


def scratch_dir(prefix: str) -> Path:
    """A new directory under the session's scratch root (conftest removes it at the end)."""
    root = os.environ.get("RTMU_GUI_TMP")
    if root:
        Path(root).mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=prefix, dir=root))


def pump(condition: Callable[[], bool], timeout: float = 5.0, what: str = "condition") -> None:
    """Run the GTK main loop until ``condition()`` is true; fail after ``timeout`` seconds (× PATIENCE)."""
    ctx = GLib.MainContext.default()
    deadline = time.monotonic() + timeout * PATIENCE
    while True:
        while ctx.pending():
            ctx.iteration(False)
        if condition():
            return
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout * PATIENCE:g} s waiting for {what}")
        ctx.iteration(False) or time.sleep(0.004)


def settle(widget: Gtk.Widget, quiet: float = 0.3, timeout: float = 5.0) -> None:
    """Wait until ``widget``'s size has not changed for ``quiet`` seconds: a resize the X server does on
    its own time (full screen without a window manager, a new default size) is over before a test
    aims a pointer at what it laid out."""
    last = [(-1, -1), time.monotonic()]

    def quiet_now() -> bool:
        size = (widget.get_width(), widget.get_height())
        now = time.monotonic()
        if size != last[0]:
            last[0], last[1] = size, now
        return now - last[1] >= quiet  # type: ignore[operator]

    pump(quiet_now, timeout, "the layout to settle")


def idle(seconds: float) -> None:
    """Let the main loop run for ``seconds`` (used only where the point is that time passes)."""
    end = time.monotonic() + seconds
    pump(lambda: time.monotonic() >= end, seconds + 5, "time to pass")


class LoopProbe:
    """A 100 ms GLib timer of the test's own, counting: proof that nothing blocks the main loop.

    (The window's own timers run only while something needs them — once a second at rest — so
    they are no measure of the loop's liveness.) ``close()`` removes it."""

    def __init__(self) -> None:
        self.beats = 0
        self._source = GLib.timeout_add(100, self._beat)

    def _beat(self) -> bool:
        self.beats += 1
        return True

    def close(self) -> None:
        if self._source:
            GLib.source_remove(self._source)
            self._source = 0


class Gui:
    """One RTMU application connected to a simulator, and what a test does with it."""

    def __init__(self, app: RtmuApplication, shots: Path, name: str) -> None:
        self.app = app
        self.shots = shots
        self.name = name
        self._shot_no = 0

    @classmethod
    def start(
        cls, shots: Path, name: str, host: str, port: int, *, connect: bool = True, user: str | None = None
    ) -> Gui:
        settings = scratch_dir("settings-") / "settings.toml"
        options = GuiOptions(
            host=host,
            port=port,
            user=user,
            settings_path=settings,
            persist=False,
            connect=None if connect else False,
        )
        return cls.open(options, shots, name, connect=connect)

    @classmethod
    def open(cls, options: GuiOptions, shots: Path, name: str, *, connect: bool = True) -> Gui:
        """The app with these options, activated as ``rtmu`` would; waits for the connection if asked."""
        app = RtmuApplication(options)
        register(app)
        gui = cls(app, shots, name)
        OPEN[id(gui)] = gui.close  # before anything can fail: a half-opened app is closed too
        app.activate()
        COUNTS["windows"] += 1
        pump(lambda: app.window is not None and app.window.get_mapped(), 10, "the window to be mapped")
        gui.focus()
        if connect:
            gui.wait_connected()
        return gui

    # -- accessors ---------------------------------------------------------------------------
    @property
    def window(self) -> MainWindow:
        assert self.app.window is not None
        return self.app.window

    @property
    def model(self) -> RobotModel:
        """The shown robot's state."""
        return self.window.model

    @property
    def operator(self) -> OperatorState:
        """The operator's speed and view choices."""
        return self.window.operator

    @property
    def stage(self):  # type: ignore[no-untyped-def]
        return self.window.stage

    @property
    def phase(self) -> Phase:
        return self.model.connection.value.phase

    def wait_connected(self, timeout: float = 10.0) -> None:
        pump(lambda: self.phase is Phase.CONNECTED, timeout, "the connection")
        pump(lambda: self.model.map.value.state in ("ready", "none", "unsupported"), timeout, "the map")
        pump(lambda: self.model.robot.value.numbers_at is not None, timeout, "the first robot status")
        if self.model.map.value.state == "ready":
            pump(lambda: self.stage.last_frame_complete, timeout, "a frame with the whole map drawn")
        self.wait_armed(timeout=timeout)

    def wait_armed(self, session: RobotSession | None = None, timeout: float = 10.0) -> None:
        """Until the window's guardian is armed for ``session`` (default: the one shown): before that
        a drive key is refused (a robot may drive only once its guardian can stop it)."""
        shown = session or self.window.session
        seat = shown.seat
        if seat is not None and shown.controller.supports("ratioDrive"):
            pump(lambda: seat.waiting_reason() is None, timeout, f"the guardian to be armed for {shown.name}")

    # -- keys ----------------------------------------------------------------------------------
    def xid(self) -> int:
        return GdkX11.X11Surface.get_xid(self.window.get_surface())

    def xdotool(self, *args: str, timeout: float = 10.0) -> None:
        self.run_tool("xdotool", *args, timeout=timeout)

    def focus(self) -> None:
        for attempt in range(5):
            try:
                self.xdotool("windowfocus", "--sync", str(self.xid()))
                break
            except AssertionError as error:
                # Under a window manager a window it is mapping again (leaving full screen) is not
                # viewable for a moment, and X refuses its focus (BadMatch): ask again once it is.
                if "BadMatch" not in str(error) or attempt == 4:
                    raise
                idle(0.3)
        pump(self.window.is_active, 5, "the window to have the keyboard focus")

    def key(self, *names: str) -> None:
        self.xdotool("key", "--delay", "30", *names)

    def keydown(self, name: str) -> None:
        self.xdotool("keydown", name)

    def keyup(self, name: str) -> None:
        self.xdotool("keyup", name)

    def centre_on_surface(self, widget: Gtk.Widget) -> tuple[int, int]:
        """Where the middle of ``widget`` is on its X window (surface), for pointer events."""
        pump(lambda: widget.get_mapped() and widget.get_width() > 0, 3, "the widget to be laid out")
        idle(0.1)
        native = widget.get_native()
        ok, point = widget.compute_point(
            native, Graphene.Point().init(widget.get_width() / 2, widget.get_height() / 2)
        )
        assert ok
        dx, dy = native.get_surface_transform()
        return round(point.x + dx), round(point.y + dy)

    def click(self, widget: Gtk.Widget) -> None:
        """A real left click (through the X server) in the middle of ``widget``."""
        x, y = self.centre_on_surface(widget)
        xid = str(GdkX11.X11Surface.get_xid(widget.get_native().get_surface()))
        self.xdotool("mousemove", "--window", xid, str(x), str(y), "click", "1")

    # -- pictures ------------------------------------------------------------------------------
    def render(self, widget: Gtk.Widget, path: Path) -> Path:
        """``widget`` as it looks now, to a PNG (the renderer of its window, as GTK itself draws it)."""
        node = None
        deadline = time.monotonic() + 3.0
        while node is None:  # right after a relayout the widget may have no render node yet
            idle(0.05)
            w, h = widget.get_width(), widget.get_height()
            snapshot = Gtk.Snapshot()
            Gtk.WidgetPaintable.new(widget).snapshot(snapshot, w, h)
            node = snapshot.to_node()
            assert node is not None or time.monotonic() < deadline, "nothing drawn"
        renderer = widget.get_native().get_renderer()
        texture = renderer.render_texture(node, Graphene.Rect().init(0, 0, w, h))
        texture.save_to_png(str(path))
        COUNTS["pictures"] += 1
        return path

    def shot(self, label: str) -> Path:
        """Save the whole window as ``<test>-<n>-<label>.png`` in the screenshot folder."""
        idle(0.2)  # let banner and toolbar animations finish: the picture shows the state, not a transition
        self._shot_no += 1
        path = self.shots / f"{self.name}-{self._shot_no:02d}-{label}.png"
        return self.render(self.window, path)

    def screen_shot(self, label: str) -> Path:
        """The whole X screen (menus and popovers are surfaces of their own, outside the window's picture)."""
        idle(0.2)
        self._shot_no += 1
        path = self.shots / f"{self.name}-{self._shot_no:02d}-{label}.png"
        screenshot(path)  # Pillow grabs the X screen itself; the server answers, not GTK
        COUNTS["pictures"] += 1
        return path

    def run_tool(self, *argv: str, timeout: float = 10.0) -> str:
        """An X client program, run while the main loop keeps running (so GTK can answer it); its stdout."""
        proc = subprocess.Popen(list(argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            pump(lambda: proc.poll() is not None, timeout, " ".join(argv))
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(2)
        out, err = proc.communicate()
        assert proc.returncode == 0, f"{argv} failed: {err.decode()}"
        return out.decode()

    def screen_rect(self, widget: Gtk.Widget) -> tuple[int, int, int, int]:
        """(x, y, width, height) of the X window of ``widget``'s surface on the screen (xwininfo)."""
        xid = GdkX11.X11Surface.get_xid(widget.get_native().get_surface())
        info = self.run_tool("xwininfo", "-id", str(xid))
        field = {k.strip(): v.strip() for k, _, v in (ln.partition(":") for ln in info.splitlines()) if v}
        return (
            int(field["Absolute upper-left X"]),
            int(field["Absolute upper-left Y"]),
            int(field["Width"]),
            int(field["Height"]),
        )

    def stage_pixels(self) -> np.ndarray:
        """The map stage as an (H, W, 3) uint8 array in its own coordinates."""
        path = scratch_dir("stage-") / "stage.png"
        self.render(self.stage, path)
        with Image.open(path) as img:
            return np.asarray(img.convert("RGB"))

    # -- teardown ------------------------------------------------------------------------------
    def close(self) -> None:
        OPEN.pop(id(self), None)
        app = self.app
        windows = list(app.get_windows())
        app.close_session()
        for w in windows:
            w.destroy()
        pump(lambda: not app.get_windows(), 5, "the windows to go")
