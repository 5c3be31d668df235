"""One simulated world: the map's obstacles, the robot, its modes, sensors and a clock.

The world knows nothing about sockets. The server steps it (``advance``) and
asks it questions; the world reports what changed that clients subscribed to
broadcasts want to hear (mode, status strings, popups) through ``changes``.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from . import p3dx
from .camera import Camera, View
from .geometry import Obstacles
from .laser import laser_readings
from .modes import JogMode, Mode, RatioDriveMode, StopMode, WanderMode
from .navmodes import DockMode, GotoMode, Localization, NavMap, PathTask, charge
from .robot import Body, normalize_deg
from .sonar import sonar_readings
from .wifi import AccessPoint, Link

PHYSICS_DT = 0.01
"""100 Hz integration in simulated time."""


@dataclass(frozen=True, slots=True)
class RobotSnapshot:
    """A copy of the robot's state, safe to hand to another thread."""

    time: float
    x: float
    y: float
    th: float
    vel: float
    rot_vel: float
    battery_v: float
    status: str
    mode: str
    mode_name: str
    extended_status: str
    trans_ratio: float
    rot_ratio: float
    throttle_ratio: float
    lat_ratio: float
    safe_drive: bool
    stalled: bool
    collisions: int
    watchdog_stops: int


@dataclass
class Popup:
    id: int
    ignore_identifier: str
    title: str
    message: str
    kind: int
    buttons: tuple[str, str, str]
    default_button: int = 0
    escape_button: int = 0
    timeout: float = 0.0
    """Seconds until the server closes it with ``timeout_text`` (0: never), as ARIA's popup handler."""
    timeout_text: str = "No answer"
    pressed: tuple[str, str, str] = ("", "", "")
    """What ``popupClose`` says after each button (ARIA's ``buttonNPressed``; "" = the button's label)."""
    created_at: float = 0.0


@dataclass
class Changes:
    """What happened since the server last looked (it broadcasts these, then clears them)."""

    mode_info: bool = False
    strings: bool = False
    dock_info: bool = False
    popups_created: list[Popup] = field(default_factory=list)
    popups_closed: list[tuple[int, str]] = field(default_factory=list)

    def clear(self) -> None:
        self.mode_info = False
        self.strings = False
        self.dock_info = False
        self.popups_created.clear()
        self.popups_closed.clear()


class World:
    def __init__(
        self,
        obstacles: Obstacles,
        *,
        home: tuple[float, float, float] = (0.0, 0.0, 0.0),
        access_point: tuple[float, float] | None = None,
        seed: int = 1,
        drive_timeout: float = 2.0,
        battery_v: float = p3dx.BATTERY_FULL_V,
    ) -> None:
        self.obstacles = obstacles
        self.rng = random.Random(seed)
        self.time = 0.0
        self.body = Body(obstacles, *home, battery_v=battery_v)
        self.stop_mode = StopMode()
        self.ratio_mode = RatioDriveMode(drive_timeout)
        self.wander_mode = WanderMode(random.Random(self.rng.random()))
        self.jog_mode = JogMode()
        self.nav_map: NavMap | None = None
        self.localization = Localization()
        self.path_task = PathTask(self)
        self.goto_mode = GotoMode(self, self.path_task)
        self.dock_mode = DockMode(self, self.path_task)
        self.modes: tuple[Mode, ...] = (
            self.stop_mode,
            self.ratio_mode,
            self.wander_mode,
            self.jog_mode,
            self.goto_mode,
            self.dock_mode,
        )
        self.mode: Mode = self.stop_mode
        self.waiting_modes: list[Mode] = []
        """Modes that asked to take over while the active one was locked, in the order they asked."""
        self._mode_info = self.mode_info()
        self.home = home
        """Where ``home`` drives to (the map's home cairn, or where the robot started)."""
        self.camera = Camera(obstacles)
        if access_point is None:
            lo_x, lo_y, hi_x, hi_y = obstacles.bounds
            access_point = ((lo_x + hi_x) / 2, (lo_y + hi_y) / 2)
        self.access_point = AccessPoint(obstacles, *access_point)
        self.changes = Changes()
        self._strings = self.strings()
        self._sonar_cache: tuple[tuple[float, float, float], list[tuple[int, int]]] | None = None
        self._laser_cache: tuple[tuple[float, float, float], list[tuple[int, int]]] | None = None
        self.popups: dict[int, Popup] = {}
        self._next_popup_id = 1
        self.popup_clicks: list[tuple[int, int]] = []
        """Every ``popupClicked`` received, (id, button), for tests to check at the simulator."""
        self.popup_flood: tuple[float, float] | None = None
        """(popups per second, until world time): a hostile server raising popups as fast as it can."""
        self._flood_due = 0.0
        self._popup_check_at = 0.0
        self._low_battery_warned = False
        self.last_activity = 0.0
        self.step_hooks: list[Callable[[], None]] = []
        """Called after every step (a scan log looking at the robot, :mod:`.mapping_data`)."""
        self.received_ratios: tuple[float, float, float, float] | None = None
        """The last ratioDrive exactly as received (the watchdog zeroes the mode's ratios, not this)."""
        self.ratio_drives_received = 0

    def replace_obstacles(self, obstacles: Obstacles) -> None:
        """A new map: the body, sensors, camera and radio all see the new walls."""
        self.obstacles = obstacles
        self.body.obstacles = obstacles
        self.camera = Camera(obstacles)
        lo_x, lo_y, hi_x, hi_y = obstacles.bounds
        self.access_point = AccessPoint(obstacles, (lo_x + hi_x) / 2, (lo_y + hi_y) / 2)
        self._sonar_cache = self._laser_cache = None

    def add_obstacles(self, segments: np.ndarray) -> None:
        """Put walls into the world that the map does not have (a box left in a corridor): the body and
        the sonar see them, the path planner only through the sonar."""
        seg = np.concatenate([self.obstacles.segments, np.asarray(segments, dtype=np.float64).reshape(-1, 4)])
        self.replace_obstacles(Obstacles(seg, self.obstacles.points, point_cell_mm=self.obstacles.cell))

    # -- modes ----------------------------------------------------------------
    def touch(self) -> None:
        """A client asked for something: the active mode is busy now."""
        self.last_activity = self.time

    def seconds_since_activity(self) -> float:
        return max(self.time - self.last_activity, 0.0)

    def activate(self, mode: Mode) -> None:
        """Make ``mode`` the active one; a locked active mode is asked to give way and ``mode`` waits."""
        self.touch()
        if mode is self.mode:
            return
        current = self.mode
        if current.locked:
            if current.will_unlock:
                if mode not in self.waiting_modes:
                    self.waiting_modes.append(mode)
                current.request_unlock()
                self.check_strings()
            return
        self.waiting_modes.clear()
        current.deactivate()
        self.mode = mode
        mode.activate(self.body, self.time)
        self.changes.mode_info = True
        self._mode_info = self.mode_info()
        self.check_strings()

    def mode_info(self) -> tuple[str, bool, bool]:
        """(name, locked, will unlock if requested): what ``getModeInfo`` reports."""
        m = self.mode
        return (m.NAME, m.locked, m.locked and m.will_unlock)

    def check_mode_info(self) -> None:
        """Flag ``getModeInfo`` for broadcast when the active mode's name or lock changed."""
        info = self.mode_info()
        if info != self._mode_info:
            self._mode_info = info
            self.changes.mode_info = True

    def home_pose(self) -> tuple[float, float, float | None]:
        return self.home

    def stop(self) -> None:
        self.activate(self.stop_mode)

    def ratio_drive(self, trans: float, rot: float, throttle: float, lat: float = 0.0) -> None:
        self.touch()
        if self.mode is not self.ratio_mode:
            self.activate(self.ratio_mode)
        self.ratio_mode.set_ratios(trans, rot, throttle, lat, self.time)
        self.received_ratios = (trans, rot, throttle, lat)
        self.ratio_drives_received += 1

    def set_safe_drive(self, safe: bool) -> None:
        """ARIA: changing safety while driving zeroes the ratios; the mode string follows."""
        mode = self.ratio_mode
        mode.safe = safe
        if self.mode is mode:
            last = mode.last_command
            mode.set_ratios(0.0, 0.0, 0.0, 0.0, self.time)
            mode.last_command = last
        self.check_strings()

    def wander(self) -> None:
        self.activate(self.wander_mode)

    def move_distance(self, distance: float) -> None:
        self.touch()
        self._jog().move(self.body, distance)
        self.check_strings()

    def turn_by(self, angle: float) -> None:
        self.touch()
        self._jog().turn_by(self.body, angle)
        self.check_strings()

    def turn_to(self, heading: float) -> None:
        self.touch()
        self._jog().turn_to(heading)
        self.check_strings()

    def lose_localization(self) -> None:
        """The robot no longer knows where it is: navigation fails until :meth:`localize_to`."""
        self.localization.lose(self.time)

    def localize_to(self, x: float, y: float, th: float) -> None:
        """``localizeToPose``: as ARNL with MobileSim, the simulated robot is put where the operator says
        (the nearest spot it fits, when that is inside something), then localizes for a moment."""
        if self.nav_map is not None and not self._on_map(x, y):
            # ARNL finds nothing of the map around a pose off it: it stays lost, the robot where it was.
            self.localization.lose(self.time)
            return
        fx, fy = free_spot_near(self.obstacles, x, y, p3dx.RADIUS_MM)
        b = self.body
        b.x, b.y, b.th = fx, fy, normalize_deg(th)
        b.vel = b.rot_vel = 0.0
        b.stalled = False
        self._sonar_cache = self._laser_cache = None
        self.localization.start(self.time)

    def _on_map(self, x: float, y: float) -> bool:
        """True when (x, y) lies within the map's extent (its lines and points, a robot's width around)."""
        lo_x, lo_y, hi_x, hi_y = self.obstacles.bounds
        margin = p3dx.RADIUS_MM
        return lo_x - margin <= x <= hi_x + margin and lo_y - margin <= y <= hi_y + margin

    def _jog(self) -> JogMode:
        if self.mode is not self.jog_mode:
            self.activate(self.jog_mode)
        return self.jog_mode

    # -- time -----------------------------------------------------------------
    def step(self, dt: float = PHYSICS_DT) -> None:
        self.time = round(self.time + dt, 9)  # no drift: 300 steps of 10 ms are exactly 3 s
        # A pack at or below shutdown stops the robot before its motors turn: a drive asked of it
        # must not move it for even one step (a status would show that step's speed).
        self._stop_on_flat_battery()
        cmd = self.mode.command(self.body, self.time, dt)
        self.body.step(dt, cmd)
        self.camera.ptz.slew(dt)
        if not self.body.is_stopped():
            self.last_activity = self.time
        if self._charging():
            charge(self, dt)
        self.localization.tick(self.time)
        if self.waiting_modes and not self.mode.locked:
            self.activate(self.waiting_modes.pop(0))
        self.check_mode_info()
        self._stop_on_flat_battery()
        self._check_battery()
        self._check_popups()
        self.check_strings()
        for hook in self.step_hooks:
            hook()

    def _charging(self) -> bool:
        return self.mode is self.dock_mode and self.dock_mode.docked

    def _stop_on_flat_battery(self) -> None:
        if (
            self.body.battery_v <= p3dx.BATTERY_SHUTDOWN_V
            and self.mode is not self.stop_mode
            and not self._charging()
        ):
            self.stop()

    def check_strings(self) -> None:
        now = self.strings()
        if now != self._strings:
            self._strings = now
            self.changes.strings = True

    def _check_battery(self) -> None:
        v = self.body.battery_v
        if not self._low_battery_warned and v <= p3dx.BATTERY_LOW_V:
            self._low_battery_warned = True
            self.create_popup(
                "Low battery",
                f"The battery is down to {v:.1f} V. Dock or charge the robot soon; "
                f"it stops at {p3dx.BATTERY_SHUTDOWN_V:.1f} V.",
                kind=2,
                buttons=("OK", "", ""),
            )

    def set_battery(self, volts: float) -> None:
        """Set the pack's voltage; crossing back above the low threshold re-arms the warning."""
        self.body.battery_v = volts
        if volts > p3dx.BATTERY_LOW_V:
            self._low_battery_warned = False

    def recharge(self) -> None:
        self.set_battery(p3dx.BATTERY_FULL_V)

    # -- popups ---------------------------------------------------------------
    def create_popup(
        self,
        title: str,
        message: str,
        *,
        kind: int = 1,
        buttons=("OK", "", ""),
        timeout: float = 0.0,
        timeout_text: str = "No answer",
        pressed: tuple[str, str, str] = ("", "", ""),
        default_button: int = 0,
        escape_button: int = 0,
    ) -> Popup:
        labels = (*buttons, "", "", "")[:3]
        popup = Popup(
            self._next_popup_id, "", title, message, kind, labels, default_button, escape_button,
            timeout, timeout_text, pressed, self.time,
        )  # fmt: skip
        self._next_popup_id += 1
        self.popups[popup.id] = popup
        self.changes.popups_created.append(popup)
        return popup

    def click_popup(self, popup_id: int, button: int) -> None:
        self.popup_clicks.append((popup_id, button))
        del self.popup_clicks[:-1000]
        popup = self.popups.pop(popup_id, None)
        if popup is None:
            return
        if 0 <= button < 3:
            text = popup.pressed[button] or f"{popup.buttons[button]} pressed"
        else:
            text = "Closed: no such button"  # a button the popup never offered
        self.changes.popups_closed.append((popup_id, text))

    def close_popup(self, popup_id: int, text: str) -> bool:
        """Close it from the server's side (its program decided): every client hears ``popupClose``."""
        if self.popups.pop(popup_id, None) is None:
            return False
        self.changes.popups_closed.append((popup_id, text))
        return True

    def flood_popups(self, per_second: float, seconds: float) -> None:
        """Raise ``per_second`` popups for ``seconds`` (each closes itself after 2 s): a hostile server."""
        self.popup_flood = (per_second, self.time + seconds) if per_second > 0 and seconds > 0 else None
        self._flood_due = self.time

    def _check_popups(self) -> None:
        flood = self.popup_flood
        if flood is not None:
            rate, until = flood
            while self._flood_due <= min(self.time, until):
                n = self._next_popup_id
                self.create_popup(
                    f"Flood <b>{n}</b> & co", f"Popup {n} of a flood: <i>plain</i> text & no markup",
                    kind=2, buttons=("OK", "Cancel", ""), timeout=2.0,
                )  # fmt: skip
                self._flood_due += 1.0 / rate
            if self.time >= until:
                self.popup_flood = None
        if self.time < self._popup_check_at:
            return
        self._popup_check_at = self.time + 0.1  # ARIA looks once a second; a tenth is close enough
        for popup in list(self.popups.values()):
            if popup.timeout > 0 and self.time - popup.created_at >= popup.timeout - 1e-9:
                self.close_popup(popup.id, popup.timeout_text)

    # -- questions --------------------------------------------------------------
    def strings(self) -> tuple[str, str, str]:
        m = self.mode
        said = held_words(self.body.holds)
        if said:  # the simulator's own words for a robot whose motors do not answer
            return (said, m.mode_string, said)
        return (m.status, m.mode_string, m.extended_status)

    def sonar(self) -> list[tuple[int, int]]:
        pose = (self.body.x, self.body.y, self.body.th)
        if self._sonar_cache is None or self._sonar_cache[0] != pose:
            self._sonar_cache = (pose, sonar_readings(self.obstacles, *pose))
        return self._sonar_cache[1]

    def laser(self) -> list[tuple[int, int]]:
        """The simulated laser's current readings (:mod:`.laser`), cached per pose like the sonar."""
        pose = (self.body.x, self.body.y, self.body.th)
        if self._laser_cache is None or self._laser_cache[0] != pose:
            self._laser_cache = (pose, laser_readings(self.obstacles, *pose))
        return self._laser_cache[1]

    def wifi(self) -> Link:
        return self.access_point.link(self.body.x, self.body.y)

    def camera_view(self, size: tuple[int, int]) -> View:
        """What a picture of ``size`` taken now would show (render it with :func:`.camera.render_view`)."""
        b = self.body
        return self.camera.view(b.x, b.y, b.th, size)

    def snapshot(self) -> RobotSnapshot:
        b, r = self.body, self.ratio_mode
        status, mode, extended = self.strings()
        return RobotSnapshot(
            self.time,
            b.x,
            b.y,
            b.th,
            b.vel,
            b.rot_vel,
            b.battery_v,
            status,
            mode,
            self.mode.NAME,
            extended,
            r.trans_ratio,
            r.rot_ratio,
            r.throttle_ratio,
            r.lat_ratio,
            r.safe,
            b.stalled,
            b.collisions,
            r.timeouts,
        )


def held_words(holds: set[str]) -> str:
    """The status the simulator shows while its e-stop is pressed or its motors are off ("" otherwise)."""
    if "estop" in holds:
        return "EStop pressed"
    if "motors" in holds:
        return "Motors disabled"
    return ""


def free_spot_near(obstacles: Obstacles, x: float, y: float, radius: float) -> tuple[float, float]:
    """(x, y) itself when the robot fits there, else the nearest point on a spiral where it does."""
    if obstacles.clearance(x, y, radius + 20) == math.inf:
        return (x, y)
    for r in np.arange(100.0, 5000.0, 100.0):
        for a in np.linspace(0, 2 * math.pi, 24, endpoint=False):
            px, py = x + r * math.cos(a), y + r * math.sin(a)
            if obstacles.clearance(px, py, radius + 20) == math.inf:
                return (float(px), float(py))
    return (x, y)
