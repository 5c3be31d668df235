"""Live video's parts: frame checks, the render stamp, the real forwarder's frames, the rate governor."""

from __future__ import annotations

import io

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
