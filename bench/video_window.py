"""The real window playing video, measured from inside its own process (run under the bench's Xvfb).

``python -m bench.video_window PORT MODE SECONDS`` opens RTMU's window on the simulator at PORT,
shows the map with the picture-in-picture, and plays the camera for SECONDS after a 2 s warm-up:

* ``live``: the live-video loop (``client.video_session``) at 20 frames/s;
* ``serial``: the baseline — one ``request_image`` per frame, the next sent only once the previous
  picture has been drawn.

It prints one JSON object: frames drawn per second, each frame's age (render stamp → texture ready,
and → first paint after it), the client's own share (received → drawn), the GTK thread's time per
frame (frame clock ``update`` → ``after-paint``, for every frame GTK drew while playing), the
process's CPU share, how often the map was drawn and the window painted, and each frame's
time per stage (:data:`STAGES`).
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import gi

from rtmu.values.intents import RequestPicture

gi.require_version("Gtk", "4.0")
from gi.repository import GLib  # noqa: E402

from rtmu.model.observables import Phase  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402


def pump(condition: Any, timeout: float) -> None:
    ctx = GLib.MainContext.default()
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError("the window did not get there in time")
        ctx.iteration(True)


def run_for(seconds: float) -> None:
    ctx = GLib.MainContext.default()
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        ctx.iteration(False) or time.sleep(0.001)


def pct(values: list[float], p: int) -> float | None:
    if len(values) < 2:
        return values[0] if values else None
    return statistics.quantiles(values, n=100, method="inclusive")[p - 1]


STAGES = ("posted", "queued", "decoded", "handed", "shown", "painted")
"""Where a frame's time goes, each measured from the one before: ``posted`` received → the model's
camera part set on the GTK thread; ``queued`` → the JPEG thread starts decoding; ``decoded`` → its
pixels are ready; ``handed`` → the GTK thread takes them (idle); ``shown`` → textures made and every
view set; ``painted`` → the frame clock's next after-paint."""


class Stages:
    """Monotonic timestamps of each frame's way from the network thread to the screen."""

    def __init__(self) -> None:
        self.marks: dict[int, dict[str, float]] = {}
        self.done: list[dict[str, float]] = []

    def _mark(self, image: Any, stage: str) -> None:
        entry = self.marks.setdefault(id(image), {"received": image.received_at})
        entry.setdefault(stage, time.monotonic())
        if len(self.marks) > 200:  # frames dropped on the way never finish: forget the oldest
            self.marks.pop(next(iter(self.marks)))

    def install(self, window: Any) -> None:
        """Wrap the window's hooks (instance attributes and the JPEG thread's module function)."""
        import rtmu.ui.camera as camera

        decoder = window.decoder
        decode, hand_over, request = camera.decode_jpeg, decoder._hand_over, decoder.decode
        by_bytes: dict[int, Any] = {}  # the JPEG thread sees only the bytes: find their image

        def decode_request(image: Any) -> None:
            self._mark(image, "posted")
            by_bytes[id(image.jpeg)] = image
            while len(by_bytes) > 50:
                by_bytes.pop(next(iter(by_bytes)))
            request(image)

        def timed_decode(data: bytes) -> Any:
            image = by_bytes.get(id(data))
            if image is not None:
                self._mark(image, "queued")
            try:
                return decode(data)
            finally:
                if image is not None:
                    self._mark(image, "decoded")

        def timed_hand_over(image: Any, decoded: Any, error: str) -> bool:
            self._mark(image, "handed")
            result: bool = hand_over(image, decoded, error)
            self._mark(image, "shown")
            return result

        decoder.decode = decode_request
        decoder._hand_over = timed_hand_over
        camera.decode_jpeg = timed_decode

    def painted(self, measuring: bool) -> None:
        now = time.monotonic()
        for key, entry in list(self.marks.items()):
            if "shown" in entry:
                entry["painted"] = now
                del self.marks[key]
                if measuring:
                    self.done.append(entry)

    def summary(self) -> dict[str, dict[str, float | None]]:
        out: dict[str, dict[str, float | None]] = {}
        previous = "received"
        for stage in STAGES:
            ms = [(e[stage] - e[previous]) * 1000 for e in self.done if stage in e and previous in e]
            out[stage] = {"p50": pct(ms, 50), "p95": pct(ms, 95)}
            previous = stage
        total = [(e["painted"] - e["received"]) * 1000 for e in self.done]
        out["total"] = {"p50": pct(total, 50), "p95": pct(total, 95)}
        return out


def main(argv: list[str]) -> int:
    port, mode, seconds = int(argv[0]), argv[1], float(argv[2])
    settings = Path(tempfile.mkdtemp(prefix="rtmu-bench-video-")) / "settings.toml"
    app = RtmuApplication(
        GuiOptions(host="127.0.0.1", port=port, settings_path=settings, persist=False, connect=None)
    )
    app.register(None)
    app.activate()
    pump(lambda: app.window is not None and app.window.get_mapped(), 20)
    window = app.window
    assert window is not None
    window.set_default_size(1024, 600)
    pump(lambda: window.model.connection.value.phase is Phase.CONNECTED, 20)
    pump(lambda: window.model.map.value.state in ("ready", "none"), 20)

    measuring = [False]
    ready_age: list[float] = []
    drawn_age: list[float] = []
    client_ms: list[float] = []
    frame_ms: list[float] = []
    drawn = [0]
    last_stamp: list[int | None] = [None]
    waiting_paint: list[tuple[int | None, float]] = []
    original = window.camera_page.picture_decoded
    stages = Stages()
    stages.install(window)

    def decoded(image: Any, textures: Any, error: str) -> None:
        original(image, textures, error)
        if textures is None or not measuring[0]:
            if mode == "serial" and textures is not None:
                waiting_paint.append((image.stamp_ns, image.received_at))
            return
        now_ns = time.time_ns()
        if image.stamp_ns is not None:
            ready_age.append((now_ns - image.stamp_ns) / 1e6)
        waiting_paint.append((image.stamp_ns, image.received_at))

    window.decoder._deliver = decoded
    clock = window.get_frame_clock()
    update_at = [0.0]

    def on_update(_clock: Any) -> None:
        update_at[0] = time.perf_counter()

    paints = [0]

    def after_paint(_clock: Any) -> None:
        done = time.perf_counter()
        paints[0] += 1
        if measuring[0] and update_at[0]:
            frame_ms.append((done - update_at[0]) * 1000)
        stages.painted(measuring[0])
        while waiting_paint:
            stamp, received = waiting_paint.pop(0)
            repeat = stamp is not None and stamp == last_stamp[0]
            last_stamp[0] = stamp
            if measuring[0] and not repeat:  # the same frame again is not a new frame
                drawn[0] += 1
                client_ms.append((time.monotonic() - received) * 1000)
                if stamp is not None:
                    drawn_age.append((time.time_ns() - stamp) / 1e6)
            if mode == "serial":
                window.session.runner.send(RequestPicture())  # the next only once this one is on screen

    clock.connect("update", on_update)
    clock.connect("after-paint", after_paint)

    if mode == "live":
        live = window.live
        live._settings_popup(live.settings_button)  # what opening the gear does: its drop-downs are made then
        assert live.fps is not None
        live.fps.set_selected(live.fps.get_model().get_n_items() - 2)  # 20 fps
        window.live.set_live(True)
    else:
        window.session.runner.send(RequestPicture())
    run_for(2.0)  # warm-up: first frames, texture upload paths
    measuring[0] = True
    cpu0, t0, draws0, paints0 = time.process_time(), time.monotonic(), window.stage.frames, paints[0]
    run_for(seconds)
    cpu, elapsed = time.process_time() - cpu0, time.monotonic() - t0
    map_draws, window_paints = window.stage.frames - draws0, paints[0] - paints0
    measuring[0] = False
    window.live.set_live(False)
    print(
        json.dumps(
            {
                "fps": drawn[0] / elapsed,
                "age_ready_p50": pct(ready_age, 50),
                "age_ready_p95": pct(ready_age, 95),
                "age_drawn_p95": pct(drawn_age, 95),
                "client_ms_p50": pct(client_ms, 50),
                "client_ms_p95": pct(client_ms, 95),
                "frame_ms_p50": pct(frame_ms, 50),
                "frame_ms_p95": pct(frame_ms, 95),
                "cpu_pct": 100 * cpu / elapsed,
                "map_draws_per_s": map_draws / elapsed,
                "paints_per_s": window_paints / elapsed,
                "stages": stages.summary(),
            }
        ),
        flush=True,
    )
    app.close_session()
    for w in list(app.get_windows()):
        w.destroy()
    pump(lambda: not app.get_windows(), 5)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
