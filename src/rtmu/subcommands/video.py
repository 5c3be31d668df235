"""``rtmu video HOST[:PORT]``: play the camera as live video, headless, and report how it went.

The request loop is :class:`rtmu.client.video_feed.VideoFeed` (the window's too);
each new frame is decoded on one worker thread — never on the network loop —
and, with ``--out``, saved once it decoded. A frame that is not a sane JPEG is
dropped with a note on stderr and the video goes on.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import statistics
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ..base.units import quantity
from ..client.roles import Role
from ._common import UsageError, add_connection_arguments, fail, run_with_client
from ._options import add_fps_option, add_quality_option
from ._output import add_force_option, check_folder
from .image import picture_problem

if TYPE_CHECKING:
    import asyncio

    from ..client.connection import AriaClient
    from ..client.video_feed import LiveFrame, VideoFeed, VideoStatus

MAX_DECODES_QUEUED = 2
"""Frames waiting for the decoder; more are counted as skipped rather than queued without end."""
MAX_NOTES = 5
FRAME_NAME = "frame_{:06d}.jpg"
FRAME_GLOB = "frame_*.jpg"


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "video",
        help=_("play the camera as live video and report frames/s, kB/s and frame age"),
        description=_(
            "Ask for camera frames one at a time (getPicture<camera>, else sendVideo), the next "
            "as soon as a frame arrives, capped by --fps; decode each, optionally save it, and report."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--seconds", type=float, default=5.0, metavar="S", help=_("how long to play (default 5)"))
    p.add_argument("--json", action="store_true", help=_("print one summary object (JSON) at the end"))
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help=_("save every decoded frame here as frame_NNNNNN.jpg (the folder is made if missing)"),
    )
    add_fps_option(p, default=15.0)
    add_quality_option(p)
    add_force_option(p, "frames saved in DIR by an earlier run")
    p.add_argument("--camera", default=None, metavar="NAME", help=_("camera name (getPicture<NAME>)"))
    p.set_defaults(handler=handle)


def _percentile(values: list[float], p: int) -> float | None:
    if not values:
        return None
    if len(values) == 1:
        return values[0]
    return statistics.quantiles(values, n=100, method="inclusive")[p - 1]


class _Player:
    """Decodes (and saves) the frames the feed hands on; keeps the figures for the summary."""

    def __init__(self, out: Path | None, quiet: bool) -> None:
        self.out = out
        self.quiet = quiet
        self.pool = concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="rtmu-video")
        self.pending: set[asyncio.Future[str | None]] = set()
        self.decoded = 0
        self.bad = 0
        self.skipped = 0
        self.bytes = 0
        self.size: tuple[int, int] = (0, 0)
        self.ages_ms: list[float] = []
        self.client_ms: list[float] = []
        self.first_ns: int | None = None
        self.last_ns: int | None = None
        self.notes: list[str] = []
        self.feed: VideoFeed | None = None

    def on_frame(self, frame: LiveFrame) -> None:
        import asyncio

        if len(self.pending) >= MAX_DECODES_QUEUED:
            self.skipped += 1
            if self.feed is not None:
                self.feed.shown(frame.sequence)  # given up on: the loop must not wait for it
            return
        future = asyncio.get_running_loop().run_in_executor(self.pool, self._decode, frame)
        self.pending.add(future)
        future.add_done_callback(lambda f: self._done(frame, f))

    def _decode(self, frame: LiveFrame) -> str | None:
        problem = picture_problem(frame.jpeg, frame.width, frame.height)
        if problem is None and self.out is not None:
            (self.out / FRAME_NAME.format(frame.sequence)).write_bytes(frame.jpeg)
        return problem

    def _done(self, frame: LiveFrame, future: asyncio.Future[str | None]) -> None:
        self.pending.discard(future)
        if self.feed is not None:
            self.feed.shown(frame.sequence)
        if future.cancelled():
            return
        ready = time.time_ns()
        error = future.exception()
        problem = str(error) if error is not None else future.result()
        if problem is not None:
            self.bad += 1
            self.note(f"frame {frame.sequence} dropped: {problem}")
            return
        self.decoded += 1
        self.bytes += len(frame.jpeg)
        self.size = (frame.width, frame.height)
        self.first_ns = self.first_ns or ready
        self.last_ns = ready
        self.client_ms.append((ready - frame.received_ns) / 1e6)
        if frame.stamp_ns is not None:
            self.ages_ms.append(max(ready - frame.stamp_ns, 0) / 1e6)

    def note(self, text: str) -> None:
        if len(self.notes) < MAX_NOTES:
            self.notes.append(text)
        if not self.quiet:
            print(_("rtmu video: {visible}").format(visible=visible(text)), file=sys.stderr)

    async def settle(self) -> None:
        import asyncio

        if self.pending:
            await asyncio.wait(list(self.pending), timeout=5.0)
        self.pool.shutdown(wait=False, cancel_futures=True)


def handle(args: argparse.Namespace) -> int:
    from ..client.video_feed import VideoFeed, video_source

    if args.seconds <= 0:
        return fail("video", "--seconds must be above 0", EXIT_USAGE)
    if args.out is not None:
        try:  # before connecting: frames are not fetched for a folder that cannot hold them
            check_folder(args.out)
            if not args.force and args.out.is_dir() and any(args.out.glob(FRAME_GLOB)):
                raise UsageError(f"{args.out} holds frames of an earlier run; give --force to replace them")
            args.out.mkdir(exist_ok=True)
        except (UsageError, OSError) as exc:
            return fail("video", str(exc), EXIT_USAGE)

    async def body(client: AriaClient) -> int:
        source = video_source(client, args.camera)
        player = _Player(args.out, quiet=False)
        last_note = [""]

        def on_status(status: VideoStatus) -> None:
            if status.note and status.note != last_note[0]:
                last_note[0] = status.note
                player.note(status.note)

        feed = VideoFeed(
            client, source, player.on_frame, on_status, fps=args.fps, quality=args.quality, max_pending=1
        )
        player.feed = feed
        started = time.monotonic()
        await feed.run(args.seconds)
        elapsed = time.monotonic() - started
        await player.settle()
        status = feed.status()
        summary: dict[str, Any] = {
            "source": source,
            "seconds": round(elapsed, 3),
            "frames": player.decoded,
            "fps": round(player.decoded / elapsed, 2) if elapsed > 0 else 0.0,
            "kbps": round(player.bytes / 1000.0 / elapsed, 1) if elapsed > 0 else 0.0,
            "width": player.size[0],
            "height": player.size[1],
            "age_ms_p50": _round(_percentile(player.ages_ms, 50)),
            "age_ms_p95": _round(_percentile(player.ages_ms, 95)),
            "client_ms_p95": _round(_percentile(player.client_ms, 95)),
            "repeats": feed.stats.repeats,
            "dropped": feed.stats.dropped + player.bad,
            "skipped": player.skipped,
            "target_fps": status.target_fps,
            "rate_fps": status.rate_fps,
            "backoff": status.backoff,
            "notes": player.notes,
        }
        if args.json:
            print(json.dumps(summary))
        else:
            age = (
                ""
                if summary["age_ms_p50"] is None
                else _(", age p50 {p50} p95 {p95}").format(
                    p50=quantity(summary["age_ms_p50"], "ms"), p95=quantity(summary["age_ms_p95"], "ms")
                )
            )
            print(
                _("{frames} frames {width}x{height} from {source} in {elapsed}: {fps}, {kbps}{age}").format(
                    frames=summary["frames"],
                    width=summary["width"],
                    height=summary["height"],
                    source=visible(source),
                    elapsed=quantity(elapsed, "s", 1),
                    fps=quantity(summary["fps"], "fps", 1),
                    kbps=quantity(summary["kbps"], "kB/s"),
                    age=age,
                )
                + (_("; {count} dropped").format(count=summary["dropped"]) if summary["dropped"] else "")
                + (
                    _(
                        "; {count} repeats (the camera had no newer picture: it is slower than asked, "
                        "not the link)"
                    ).format(count=summary["repeats"])
                    if summary["repeats"]
                    else ""
                )
                + (f"; {visible(status.backoff)}" if status.backoff else "")
            )
        if player.decoded == 0:
            why = player.notes[-1] if player.notes else "the server sent no usable frame"
            return fail("video", f"no frame could be shown: {why}", EXIT_CONNECTION)
        return EXIT_OK

    return run_with_client("video", args, body, role=Role.OBSERVER)


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 1)
