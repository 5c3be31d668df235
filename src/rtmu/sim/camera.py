"""A forward camera on the robot: ray-cast the map's walls into a first-person JPEG.

One ray per image column (numpy, all columns at once) finds the nearest wall;
its distance gives the wall's height on screen and its brightness (nearer is
taller and lighter). Floor and ceiling are shaded bands. The camera has a
VC-C4-like pan/tilt/zoom head, so ``setCameraAbs`` and friends change the view.

A :class:`View` is a frozen copy of everything a picture depends on, so it can
be rendered on another thread while the world moves on; :mod:`.video` decides
when to render and shares each frame between clients.
"""

from __future__ import annotations

import io
import math
import time
from dataclasses import dataclass

import numpy as np
from PIL import Image

from .geometry import Obstacles

SIZES = ((320, 240), (640, 480))
DEFAULT_SIZE = (320, 240)
MAX_JPEG_BYTES = 31988 - 2 - 32
"""A frame must fit one packet with its width, height, stamp comment and the forwarder's 2 trailing bytes."""
MAX_SIDE = 1920

CAMERA_X_MM = 100.0
"""Mounted on the top plate, a little ahead of the centre of rotation."""
CAMERA_HEIGHT_MM = 450.0
WALL_HEIGHT_MM = 2000.0
VIEW_RANGE_MM = 25000.0
WIDE_FOV_DEG = 48.0
TELE_FOV_DEG = 4.0

# VC-C4 limits, as ARIA's camera handler reports them (protocol §4.6).
PAN_RANGE = (-98.0, 98.0)
TILT_RANGE = (-30.0, 88.0)
ZOOM_RANGE = (0.0, 100.0)
PAN_SPEED = 90.0
TILT_SPEED = 69.0
"""Degrees per second: the VC-C4's fastest pan and tilt slews, ARIA's defaults for that head."""
ZOOM_SPEED = 50.0
"""Percent of the zoom range per second (a whole range in 2 s: our choice, ARIA names no zoom speed)."""


def _toward(now: float, goal: float, step: float) -> float:
    return goal if abs(goal - now) <= step else now + math.copysign(step, goal - now)


@dataclass
class PanTiltZoom:
    """The head as it is now; a move (:meth:`aim`) sets a goal that :meth:`slew` reaches at the head's
    speeds, so a client reading the position sees it move, as a real head moves. Setting ``pan`` …
    directly (tests: "someone else moved the head") moves it at once."""

    pan: float = 0.0
    tilt: float = 0.0
    zoom: float = 0.0
    """Percent of the zoom range."""
    goal: tuple[float, float, float] | None = None
    """Where the head is turning to (clamped), None when it is still."""

    def target(self) -> tuple[float, float, float]:
        """Where the head will be: its goal, or where it is (relative moves add to this, as ARIA's
        VC-C4 driver adds to the position it last asked for)."""
        return self.goal if self.goal is not None else (self.pan, self.tilt, self.zoom)

    def aim(self, pan: float, tilt: float, zoom: float) -> None:
        """Start turning to (pan, tilt, zoom), clamped to the head's limits."""
        self.goal = (
            min(max(pan, PAN_RANGE[0]), PAN_RANGE[1]),
            min(max(tilt, TILT_RANGE[0]), TILT_RANGE[1]),
            min(max(zoom, ZOOM_RANGE[0]), ZOOM_RANGE[1]),
        )

    def slew(self, dt: float) -> None:
        """Move ``dt`` seconds' worth toward the goal; the goal is dropped once reached."""
        if self.goal is None:
            return
        pan, tilt, zoom = self.goal
        self.pan = _toward(self.pan, pan, PAN_SPEED * dt)
        self.tilt = _toward(self.tilt, tilt, TILT_SPEED * dt)
        self.zoom = _toward(self.zoom, zoom, ZOOM_SPEED * dt)
        if (self.pan, self.tilt, self.zoom) == self.goal:
            self.goal = None

    @property
    def fov_deg(self) -> float:
        # Zoom in equal optical steps: the field of view shrinks geometrically.
        ratio = TELE_FOV_DEG / WIDE_FOV_DEG
        return WIDE_FOV_DEG * ratio ** (self.zoom / 100.0)


@dataclass(frozen=True, slots=True)
class View:
    """What the camera sees from: robot pose (mm, mm, degrees), head settings, picture size and the walls.

    Equal views give equal pictures (pose rounded to 1 mm and 0.1 degree; the walls compared by identity).
    """

    x: float
    y: float
    th: float
    pan: float
    tilt: float
    zoom: float
    size: tuple[int, int]
    obstacles: Obstacles


class Camera:
    def __init__(self, obstacles: Obstacles) -> None:
        self.obstacles = obstacles
        self.ptz = PanTiltZoom()

    def view(self, x: float, y: float, th: float, size: tuple[int, int]) -> View:
        """A snapshot of what a picture from robot pose (x, y, th degrees) would show now."""
        p = self.ptz
        return View(
            float(round(x)),
            float(round(y)),
            round(th, 1),
            round(p.pan, 2),
            round(p.tilt, 2),
            round(p.zoom, 2),
            size,
            self.obstacles,
        )

    def render(self, x: float, y: float, th: float, size: tuple[int, int]) -> np.ndarray:
        """An (h, w, 3) uint8 picture from robot pose (x, y, th degrees)."""
        return render_view(self.view(x, y, th, size))


def render_view(view: View) -> np.ndarray:
    """An (h, w, 3) uint8 picture of ``view``. Touches nothing shared, so it may run on a worker thread."""
    return render_rgbx(view)[..., :3]


def render_rgbx(view: View) -> np.ndarray:
    """An (h, w, 4) uint8 RGBX picture of ``view`` (4th byte padding): the renderer's native form."""
    x, y, th = view.x, view.y, view.th
    w, h = view.size
    ptz = PanTiltZoom(view.pan, view.tilt, view.zoom)
    f = (w / 2) / math.tan(math.radians(ptz.fov_deg) / 2)
    heading = math.radians(th - ptz.pan)  # ARIA's pan is positive to the right (clockwise)
    t = math.radians(th)
    cx = x + CAMERA_X_MM * math.cos(t)
    cy = y + CAMERA_X_MM * math.sin(t)
    cols = np.arange(w, dtype=np.float64)
    offsets = np.arctan((w / 2 - cols - 0.5) / f)
    dist = view.obstacles.cast(cx, cy, heading + offsets, VIEW_RANGE_MM)
    perp = dist * np.cos(offsets)
    horizon = h / 2 + f * math.tan(math.radians(ptz.tilt))
    rows = np.arange(h, dtype=np.float64)[:, None]
    background = _background(h, horizon)

    finite = np.isfinite(perp)
    safe_perp = np.where(finite, np.maximum(perp, 1.0), 1.0)
    top = horizon - f * (WALL_HEIGHT_MM - CAMERA_HEIGHT_MM) / safe_perp
    bottom = horizon + f * CAMERA_HEIGHT_MM / safe_perp
    wall = finite[None, :] & (rows >= top[None, :]) & (rows <= bottom[None, :])
    light = np.clip(1.15 - safe_perp / 9000.0, 0.25, 1.0)
    wall_colour = np.array([225.0, 205.0, 170.0])[None, :] * light[:, None]
    # A darker skirting band at the foot of the wall gives a sense of the floor line.
    skirting = (rows > bottom[None, :] - np.maximum((bottom - top) * 0.06, 1.0)[None, :]) & wall
    # Whole-picture work is done on one uint32 per pixel (R, G, B, X little-endian): a masked copy of
    # 4-byte words is about ten times cheaper than choosing among (h, w, 3) byte triples.
    wall_px = _pack(wall_colour)
    img = np.empty((h, w), dtype="<u4")
    img[:] = _pack(background)[:, None]
    np.copyto(img, np.broadcast_to(wall_px[None, :], (h, w)), where=wall)
    np.copyto(img, np.broadcast_to(_pack(wall_colour * 0.6)[None, :], (h, w)), where=skirting)
    return img.view(np.uint8).reshape(h, w, 4)


def _pack(rgb: np.ndarray) -> np.ndarray:
    """(n, 3) colours (0…255, any dtype) → n uint32 words whose little-endian bytes are R, G, B, 255."""
    c = np.clip(rgb, 0, 255).astype("<u4")
    return c[:, 0] | (c[:, 1] << 8) | (c[:, 2] << 16) | np.uint32(0xFF000000)


def _background(h: int, horizon: float) -> np.ndarray:
    """One (h, 3) uint8 column: ceiling (darker towards the horizon), floor (lighter near the robot)."""
    rows = np.arange(h, dtype=np.float64)[:, None]
    above = np.clip((horizon - rows) / max(h, 1), 0.0, 1.0)
    below = np.clip((rows - horizon) / max(h, 1), 0.0, 1.0)
    sky = np.array([170.0, 180.0, 195.0])
    floor = np.array([95.0, 85.0, 75.0])
    column = np.where(rows < horizon, sky * (0.75 + 0.25 * above), floor * (0.55 + 0.9 * below))
    return np.clip(column, 0, 255).astype(np.uint8)


def render_jpeg(view: View, quality: int) -> bytes:
    """``view`` rendered, encoded and stamped: the whole cost of one frame, in one call for a worker."""
    return render_frame(view, quality)[1]


def render_frame(view: View, quality: int) -> tuple[np.ndarray, bytes]:
    """``view`` rendered (its RGBX pixels, kept for :func:`refresh_frame`) and as a stamped JPEG."""
    pixels = render_rgbx(view)
    return pixels, stamp_jpeg(encode_jpeg(pixels, quality), time.time_ns())


SENSOR_NOISE = 3
"""± levels of a camera sensor's noise: enough that two frames of one view are never equal."""


def refresh_frame(pixels: np.ndarray, quality: int, seed: int) -> tuple[np.ndarray, bytes]:
    """A new frame of a view that did not change, as a real camera delivers it: the same scene with
    fresh sensor noise, encoded and stamped now (no ray casting: the scene's pixels are reused)."""
    noise = np.random.default_rng(seed).integers(-SENSOR_NOISE, SENSOR_NOISE + 1, pixels.shape[:2])
    noisy = np.clip(pixels[..., :3].astype(np.int16) + noise[..., None], 0, 255).astype(np.uint8)
    return pixels, stamp_jpeg(encode_jpeg(noisy, quality), time.time_ns())


STAMP_PREFIX = b"RTMU-T="
"""The render-time comment clients read to measure a frame's age end to end (wall-clock ns)."""


def stamp_jpeg(jpeg: bytes, wall_ns: int) -> bytes:
    """``jpeg`` with a COM segment ``RTMU-T=<wall_ns>`` after its JFIF header (decoders skip comments)."""
    text = STAMP_PREFIX + str(wall_ns).encode()
    comment = b"\xff\xfe" + (len(text) + 2).to_bytes(2, "big") + text
    at = 2
    if jpeg[2:4] == b"\xff\xe0":  # keep JFIF's APP0 first, where readers expect it
        at = 4 + int.from_bytes(jpeg[4:6], "big")
    return jpeg[:at] + comment + jpeg[at:]


def encode_jpeg(pixels: np.ndarray, quality: int) -> bytes:
    """JPEG bytes small enough for one ArNetworking packet (quality is lowered until it fits).

    ``pixels`` is (h, w, 3) RGB or (h, w, 4) RGBX (encoded without a copy).
    """
    h, w = pixels.shape[:2]
    if pixels.shape[2] == 4 and pixels.flags.c_contiguous:
        image = Image.frombuffer("RGBX", (w, h), pixels, "raw", "RGBX", 0, 1)
    else:
        image = Image.fromarray(np.ascontiguousarray(pixels[..., :3]), "RGB")
    q = int(min(max(quality, 1), 95))
    while True:
        buf = io.BytesIO()
        image.save(buf, "JPEG", quality=q)
        data = buf.getvalue()
        if len(data) <= MAX_JPEG_BYTES or q <= 5:
            return data
        q = max(5, q - 10)
