"""``rtmu ptz HOST[:PORT]``: the server's cameras, the pan-tilt-zoom head's limits and position; set it.

Reads ``getCameraList``, then ``getCameraInfo<N>`` and ``getCameraData<N>`` of the first camera
that can be moved (see :mod:`rtmu.client.ptz`). ``--pan/--tilt/--zoom`` point it absolutely
(``setCameraAbs<N>``; an axis left out keeps its current value) and print where it went.
Exit 4 when the server has no movable camera head.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_UNSUPPORTED
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.roles import Role
from ..values.state import PtzState
from ._common import UsageError, add_connection_arguments, fail, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient

PTZ_COMMANDS = ("setCameraRel", "setCameraAbs", "setCameraPct", "getCameraData", "getCameraInfo")


def _angle(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value) or abs(value) > 327.67:
        raise argparse.ArgumentTypeError(f"{text} is out of range (±327.67)")
    return value


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "ptz",
        help=_("the camera head: cameras, limits, position; --pan/--tilt/--zoom point it"),
        description=(
            _(
                "List the server's cameras (getCameraList) and show the pan-tilt-zoom head's limits and "
                "position; with --pan/--tilt/--zoom point it there (setCameraAbs) and show where it went. "
                "A value outside the head's own limits (as the server reports them) is refused with those "
                "limits (exit 2). Exit 4 when the server has no movable camera head. Moving the head never "
                "moves the robot."
            )
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--json", action="store_true", help=_("one JSON object: cameras, limits, position"))
    p.add_argument("--pan", type=_angle, metavar="DEG", help=_("pan to this angle (degrees, right positive)"))
    p.add_argument("--tilt", type=_angle, metavar="DEG", help=_("tilt to this angle (degrees, up positive)"))
    p.add_argument("--zoom", type=_angle, metavar="PCT", help=_("zoom to this point of its range (%%)"))
    p.set_defaults(handler=handle)


def _ptz_object(state: PtzState) -> dict[str, Any]:
    position = state.position
    return {
        "camera": state.camera,
        "pan_range": list(state.pan_range),
        "tilt_range": list(state.tilt_range),
        "zoom_range": list(state.zoom_range),
        "zoom_available": state.zoom_available,
        "position": None
        if position is None
        else {"pan": position[0], "tilt": position[1], "zoom": position[2]},
    }


def handle(args: argparse.Namespace) -> int:
    from ..client.detached import DetachedContext
    from ..client.ptz import PtzFeed
    from ..client.session_config import SessionConfig

    moving = any(v is not None for v in (args.pan, args.tilt, args.zoom))

    async def body(client: AriaClient) -> int:
        feed = PtzFeed(DetachedContext(client, config=SessionConfig(reply_timeout=args.timeout)))
        await feed.read_head(client)
        if feed.read_error is not None:  # a lost link, a silent or malformed reply: its own code, not 4
            raise feed.read_error
        state = feed.state
        if moving and state.movable and state.can_abs:
            outside = _outside_limits(args, state)
            if outside:
                raise UsageError(outside)
            pan, tilt, zoom = state.position or (0.0, 0.0, 0.0)
            feed.move_abs(
                pan if args.pan is None else args.pan,
                tilt if args.tilt is None else args.tilt,
                zoom if args.zoom is None else args.zoom,
            )
            await feed.wait_settled()  # read until the head stops, not a guessed pause
            state = feed.state
        cameras = [
            {
                "name": c.name,
                "type": c.camera_type,
                "display_name": c.display_name,
                "commands": [name for name in PTZ_COMMANDS if c.data_name(name)],
            }
            for c in feed.cameras
        ]
        if args.json:
            print_json(
                {
                    "cameras": cameras,
                    "ptz": None if state.reason else _ptz_object(state),
                    "reason": state.reason,
                }
            )
        else:
            for c in cameras:
                offered = ", ".join(c["commands"]) or "no pan/tilt/zoom commands"
                print(visible(f"{c['name']} ({c['type'] or 'unknown type'}): {offered}"))
            if not state.reason:
                _print_head(state)
        if state.reason:
            return fail("ptz", state.reason, EXIT_UNSUPPORTED)
        if moving and not state.can_abs:
            return fail("ptz", "this camera cannot be pointed absolutely (no setCameraAbs)", EXIT_UNSUPPORTED)
        return EXIT_OK

    return run_with_client("ptz", args, body, role=Role.OBSERVER)


def _outside_limits(args: argparse.Namespace, state: PtzState) -> str:
    """Why a wanted position is outside what the head reports it can do ("" when it is not)."""
    wanted = [("--pan", args.pan, state.pan_range, "°"), ("--tilt", args.tilt, state.tilt_range, "°")]
    if state.zoom_available:
        wanted.append(("--zoom", args.zoom, state.zoom_range, " %"))
    elif args.zoom is not None:
        return "this camera head has no zoom (--zoom cannot be used)"
    for option, value, (low, high), unit in wanted:
        known = low < high  # a head that reports no limits (0…0) is left to clamp on its own
        if value is not None and known and not low <= value <= high:
            return f"{option} {value:g} is outside this head's limits: {low:g}…{high:g}{unit}"
    return ""


def _print_head(state: PtzState) -> None:
    (p0, p1), (t0, t1), (z0, z1) = state.pan_range, state.tilt_range, state.zoom_range
    print(visible(f"head {state.camera}: pan {p0:g}…{p1:g}°, tilt {t0:g}…{t1:g}°"), end="")
    print(_(", zoom {z0:g}…{z1:g} %").format(z0=z0, z1=z1) if state.zoom_available else _(", no zoom"))
    if state.position is None:
        print(_("position: not read"))
    else:
        pan, tilt, zoom = state.position
        print(
            _("position: pan {pan:g}°, tilt {tilt:g}°, zoom {zoom:g} %").format(pan=pan, tilt=tilt, zoom=zoom)
        )
