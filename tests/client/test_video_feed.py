"""Live video's parts: frame checks, the render stamp, the real forwarder's frames, the rate governor."""

from __future__ import annotations

import io
import itertools

import pytest
from PIL import Image

from rtmu.capture import open_capture
from rtmu.capture.conversation import DecodedPacket
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.client.video_feed import BadFrame, FrameStats, RateGovernor, check_frame, frame_stamp, parse_frame
from rtmu.protocol.payloads.camera import VideoFrame
from rtmu.sim.camera import stamp_jpeg
from testdata import CAPTURES

CAPTURE = CAPTURES / "getVideoExample-serverDemo.pcap"


def jpeg(width: int = 64, height: int = 48) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", (width, height), (200, 30, 30)).save(out, "JPEG")
    return out.getvalue()


def test_the_stamp_survives_decoding_and_reads_back() -> None:
    stamped = stamp_jpeg(jpeg(), 1_764_000_000_123_456_789)
    assert frame_stamp(stamped) == 1_764_000_000_123_456_789
    assert frame_stamp(jpeg()) is None
    with Image.open(io.BytesIO(stamped)) as img:
        img.load()
        assert img.size == (64, 48)
    assert check_frame(stamped, 64, 48) == (1_764_000_000_123_456_789, (64, 48))


@pytest.mark.parametrize(
    ("data", "width", "height", "words"),
    [
        (b"GIF89a" + b"\x00" * 300, 64, 48, "not a JPEG"),
        (jpeg()[:-40], 64, 48, "cut short"),
        (jpeg(), 9000, 48, "over the 8192x8192 limit"),
        (jpeg(32, 24), 64, 48, "says 64x48 but the picture is 32x24"),
        (b"\xff\xd8\xff\xd9", 0, 0, "no frame header"),
    ],
    ids=["not-jpeg", "cut-short", "huge-claim", "lying-size", "empty"],
)
def test_a_bad_frame_is_named(data: bytes, width: int, height: int, words: str) -> None:
    with pytest.raises(BadFrame, match=words):
        check_frame(data, width, height)


def test_a_stamp_in_a_hostile_comment_is_bounded() -> None:
    base = jpeg()
    text = b"RTMU-T=" + b"9" * 5000
    hostile = base[:2] + b"\xff\xfe" + (len(text) + 2).to_bytes(2, "big") + text + base[2:]
    assert frame_stamp(hostile) is None  # too many digits for a clock: ignored, frame still fine
    assert check_frame(hostile, 64, 48)[1] == (64, 48)


def forwarder_frames() -> list[DecodedPacket]:
    source = open_capture(CAPTURE)
    decoder = CaptureDecoder()
    packets = [item for item in decoder.run(source.events()) if isinstance(item, DecodedPacket)]
    return [p for p in packets if p.name == "sendVideo" and p.direction == "s2c" and p.is_data]


def test_real_aria_forwarder_frames_parse_with_their_two_trailing_bytes() -> None:
    frames = forwarder_frames()
    assert frames, "the capture holds the forwarder's sendVideo replies"
    for packet in frames:
        frame, stamp = parse_frame(packet.payload)
        assert stamp is None  # ARIA does not stamp
        assert (frame.width, frame.height) == (320, 240)
        assert frame.jpeg.endswith(b"\xff\xd9") and len(frame.trailing) == 2
        assert packet.payload == VideoFrame(frame.width, frame.height, frame.jpeg, frame.trailing).encode()
        with Image.open(io.BytesIO(frame.jpeg)) as img:
            img.load()
            assert img.size == (320, 240)


def test_the_governor_backs_off_when_slow_and_recovers_when_healthy() -> None:
    g = RateGovernor(20.0, rtt_limit=0.5, age_limit=1.0)
    g.observe(0.0, 0.05, 0.04)
    assert g.rate_fps == 20.0 and g.reason == ""
    g.observe(1.0, 0.9, 0.04)
    assert g.rate_fps == 10.0 and "round trip 900 ms" in g.reason
    g.observe(2.0, 0.05, 1.6)
    assert g.rate_fps == 5.0 and "1600 ms old" in g.reason
    for t in range(3, 20):
        g.observe(float(t), 0.05, 0.04)
    assert g.rate_fps == 20.0 and g.reason == ""


def test_stats_give_rates_over_the_window_and_age_percentiles() -> None:
    s = FrameStats(window=2.0)
    for i in range(21):
        s.add(i * 0.1, 10_000, float(i))
    fps, kbps = s.rates(2.0)
    assert fps == pytest.approx(10.0, rel=0.01)
    assert kbps == pytest.approx(100.0, rel=0.06)
    assert s.age_percentile(50) == pytest.approx(10.0)
    assert s.rates(30.0) == (0.0, 0.0)


def test_a_repeated_old_frame_does_not_slow_the_video_down() -> None:
    """A still robot's camera sends the same stamped picture again and again: its age grows, but
    that is the scene standing still, not a late link (rtmu video once backed off to 0.5 fps)."""
    from rtmu.client.video_feed import VideoFeed

    now = [0.0]
    stamp = 1_000_000_000_000
    wall = [stamp + 5_000_000]  # the first copy arrives 5 ms after its render
    feed = VideoFeed(
        None, "getPictureCam1", lambda _f: None, fps=15, clock=lambda: now[0], wall_ns=lambda: wall[0]
    )  # type: ignore[arg-type]
    payload = VideoFrame(64, 48, stamp_jpeg(jpeg(), stamp)).encode()
    assert feed.take(payload, 0.01) is not None
    for _ in range(40):  # the same picture for 4 s more
        now[0] += 0.1
        wall[0] += 100_000_000
        assert feed.take(payload, 0.01) is None
    assert feed.stats.repeats == 40
    assert feed.governor.reason == "" and feed.governor.rate_fps == 15
    # …while a NEW frame that is really 3 s old still makes it back off.
    late = VideoFrame(64, 48, stamp_jpeg(jpeg(), wall[0] - 3_000_000_000)).encode()
    feed.take(late, 0.01)
    assert "old" in feed.governor.reason


# -- pacing: the camera's period learned from its repeats (issue 28) ---------------------------------
def play_camera(
    pacer: object, *, fps: float, seconds: float, ready_at, warm_up: float = 3.0, start: float = 0.0
):  # type: ignore[no-untyped-def]
    """Drive ``pacer`` against a camera model on a simulated clock from ``start``: ``ready_at(t, last)``
    is the id of the newest frame a request arriving at ``t`` gets, and when it was made (``last``: the
    id the one before got). Returns (requests, new frames, ages in s of each new frame on arrival)
    counted after ``warm_up``."""
    t, last, requests, new, ages = start, -1, 0, 0, []
    warm_up += start
    while t < warm_up + seconds:
        frame, made = ready_at(t + 0.001, last)
        got = t + 0.002
        outcome = "new" if frame != last else "repeat"
        if t >= warm_up:
            requests += 1
            if outcome == "new":
                new += 1
                ages.append(got - made)
        last = frame
        t = max(got, pacer.after(t, outcome, 1.0 / fps))  # type: ignore[attr-defined]
    return requests, new, ages


def periodic(period: float, phase: float = 0.037):  # type: ignore[no-untyped-def]
    """ARIA's video forwarder: a new picture every ``period`` on its own clock."""

    def ready_at(t: float, _last: int) -> tuple[int, float]:
        n = int((t - phase) // period)
        return n, phase + n * period

    return ready_at


def on_request(period: float):  # type: ignore[no-untyped-def]
    """The simulator: a request after ``period`` since the last new picture makes the next one."""
    made = [-1.0]

    def ready_at(t: float, last: int) -> tuple[int, float]:
        if t - made[0] >= period:
            made[0] = t
            return last + 1, t
        return last, made[0]

    return ready_at


@pytest.mark.parametrize("fps", [30.0, 15.0])
@pytest.mark.parametrize("camera", ["periodic", "on_request"])
def test_the_pacer_asks_about_once_per_new_frame_and_soon_after_it(fps: float, camera: str) -> None:
    from rtmu.client.video_feed import FramePacer

    ready = periodic(0.1) if camera == "periodic" else on_request(0.1)
    pacer = FramePacer()
    requests, new, ages = play_camera(pacer, fps=fps, seconds=20.0, ready_at=ready)
    assert new >= 0.95 * 20 * 10 * (0.95 if camera == "on_request" else 1.0)  # no frame left out
    assert requests <= 1.1 * new, (requests, new)  # ≤ 1.2 against a real server's timing (bench)
    assert pacer.period == pytest.approx(0.1, rel=0.05)
    assert sorted(ages)[int(0.95 * len(ages))] < 0.015  # each picture fetched soon after it was made


def test_a_camera_faster_than_the_setting_is_paced_by_the_setting() -> None:
    from rtmu.client.video_feed import FramePacer

    requests, new, _ = play_camera(FramePacer(), fps=5.0, seconds=10.0, ready_at=periodic(0.02))
    assert requests == new and 48 <= new <= 52


def test_a_camera_that_makes_no_new_pictures_is_asked_about_once_a_second() -> None:
    from rtmu.client.video_feed import FramePacer

    requests, new, _ = play_camera(FramePacer(), fps=30.0, seconds=20.0, ready_at=lambda t, last: (0, 0.0))
    assert new == 0 and requests <= 25


def test_a_camera_that_slows_down_is_followed() -> None:
    from rtmu.client.video_feed import FramePacer

    pacer = FramePacer()
    play_camera(pacer, fps=30.0, seconds=5.0, ready_at=periodic(0.1))
    requests, new, _ = play_camera(pacer, fps=30.0, seconds=20.0, ready_at=periodic(0.2), start=8.0)
    assert pacer.period == pytest.approx(0.2, rel=0.05)
    assert requests <= 1.25 * new and new >= 0.9 * 20 * 5


def test_a_frame_held_up_costs_a_few_retries_not_one_every_3_ms() -> None:
    """A camera (or a loaded robot computer) that holds a frame up for 40 ms: the retries start quick
    and grow, so the wait costs five requests where eight 3 ms retries and more cost nine."""
    from rtmu.client.video_feed import RETRY_MAX_S, RETRY_MIN_S, FramePacer

    pacer = FramePacer()
    sent, asked = 0.0, []
    for _ in range(30):
        sent = pacer.after(sent, "repeat", 1 / 30)
        asked.append(sent)
    gaps = [b - a for a, b in itertools.pairwise([0.0, *asked])]
    assert gaps[0] == pytest.approx(RETRY_MIN_S)  # a frame just late is still found within 3 ms
    assert all(b >= a - 1e-9 for a, b in itertools.pairwise(gaps))
    assert sum(1 for t in asked if t <= 0.040) <= 5
    assert gaps[-1] == pytest.approx(RETRY_MAX_S)  # a camera that stopped: asked once a second
