"""``rtmu watch HOST[:PORT] [--json] [--seconds S]``: one line per server event, as it happens.

Subscribes to the server's broadcasts only (interval −1) — popups opened and closed, the active
mode, the status strings, map, goals and configuration updated — so a script can follow a robot
without polling. The popups already open are listed first (``popupList``). Lines show server text
escaped (:func:`rtmu.base.textsafe.visible`); ``--json`` gives one object per line with the exact
strings. Exit 0 after ``--seconds``; 3 when the connection ends; Ctrl-C ends it as every command.
"""

from __future__ import annotations

import argparse
import contextlib
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK
from ..base.i18n import N_, Said, _, number
from ..base.textsafe import visible
from ..client.errors import NotSupported
from ..client.roles import Role
from ..protocol.errors import ProtocolError
from ..protocol.payloads.popup import PopupClose, PopupCreate, PopupType
from ..protocol.payloads.robot import ModeInfo, UpdateStrings
from ._common import add_connection_arguments, positive_float, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.call_values import Packet
    from ..client.connection import AriaClient

PLAIN_EVENTS = {
    "mapUpdated": ("map_updated", N_("map updated")),
    "goalsUpdated": ("goals_updated", N_("goals updated")),
    "configUpdated": ("config_updated", N_("configuration updated")),
}
"""Broadcasts that carry nothing worth printing beyond "it happened": (JSON event, text line, marked)."""
WATCHED = ("popupCreate", "popupClose", "getModeInfo", "updateStrings", *PLAIN_EVENTS)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "watch",
        help=_("follow the server's events: popups, mode and status changes, map/goals/config updates"),
        description=_(
            "Print one line per server event as it happens (popups opened and closed, mode "
            "and status changes, map, goals and configuration updated); the popups already open first. "
            "Exit 0 after --seconds, 3 when the connection ends, 4 when the server broadcasts none of these."
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json", action="store_true", help=_("one JSON object per line (event, t, and its fields)")
    )
    p.add_argument("--seconds", type=positive_float, metavar="S", help=_("stop after S seconds (exit 0)"))
    p.set_defaults(handler=handle)


POPUP_TYPE_WORDS = {
    "none": N_("none"),
    "information": N_("information"),
    "warning": N_("warning"),
    "critical": N_("critical"),
    "question": N_("question"),
}
"""A popup's type (ARIA's ``PopupType``, its JSON name) as the text line says it (marked)."""


def popup_type(number: int) -> str:
    with contextlib.suppress(ValueError):
        return PopupType(number).name.lower()
    return str(number)


def describe(name: str, payload: Any) -> tuple[dict[str, Any], str] | None:
    """(JSON object without ``t``, text line) for one broadcast; None for one not worth a line. The line
    is in the operator's language; the server's words in it (titles, messages, buttons, mode and status)
    as sent, escaped; the JSON keeps the exact strings and English names."""
    if isinstance(payload, PopupCreate):
        buttons = [b for b in payload.buttons if b]
        kind = popup_type(payload.popup_type)
        obj = {
            "event": "popup_opened", "id": payload.popup_id, "type": kind,
            "title": payload.title, "message": payload.message, "buttons": buttons,
        }  # fmt: skip
        labels = "|".join(visible(b) for b in buttons)
        text = _("popup opened #{id} ({type}) {title}: {message} [{buttons}]").format(
            id=payload.popup_id,
            type=_(POPUP_TYPE_WORDS.get(kind, kind)),
            title=visible(payload.title),
            message=visible(payload.message),
            buttons=labels,
        )
        return obj, text
    if isinstance(payload, PopupClose):
        obj = {"event": "popup_closed", "id": payload.popup_id, "message": payload.message}
        return obj, _("popup closed #{id}: {message}").format(
            id=payload.popup_id, message=visible(payload.message)
        )
    if isinstance(payload, ModeInfo):
        obj = {"event": "mode", "mode": payload.mode_name, "locked": payload.locked}
        mode = visible(payload.mode_name) or _("(none)")
        return obj, (_("mode {mode} (locked)") if payload.locked else _("mode {mode}")).format(mode=mode)
    if isinstance(payload, UpdateStrings):
        obj = {"event": "status", "status": payload.status, "mode": payload.mode}
        line = _("status {status} ({mode})").format(
            status=visible(payload.status), mode=visible(payload.mode)
        )
        return obj, line
    if name in PLAIN_EVENTS:
        event, text = PLAIN_EVENTS[name]
        return {"event": event}, _(text)
    return None


def handle(args: argparse.Namespace) -> int:
    import asyncio

    started = time.monotonic()

    def show(name: str, payload: Any) -> None:
        described = describe(name, payload)
        if described is None:
            return
        obj, text = described
        t = round(time.monotonic() - started, 3)
        if args.json:
            print_json({"t": t, **obj})
        else:
            print(f"{number(t, 3):>8}  {text}", flush=True)

    def handler(name: str) -> Callable[[Packet], None]:
        def on_packet(packet: Packet) -> None:
            if name in PLAIN_EVENTS:
                show(name, None)
                return
            try:
                payload = packet.decode()
            except ProtocolError:
                return  # a malformed broadcast is no event: skip it, keep watching
            show(name, payload)

        return on_packet

    async def body(client: AriaClient) -> int:
        offered = [name for name in WATCHED if client.supports(name)]
        if not offered:
            raise NotSupported(
                "popupCreate", Said(N_("this server broadcasts none of the events rtmu watch follows"))
            )
        for name in offered:
            client.request(name, -1, handler(name))
        if client.supports("popupCreate") and client.supports("popupList"):
            await client.request_once("popupList", timeout=args.timeout)  # the open ones, as events
        loop = asyncio.get_running_loop()
        end = None if args.seconds is None else loop.time() + args.seconds
        while end is None or loop.time() < end:
            if client.closed_error is not None:
                raise client.closed_error
            await asyncio.sleep(0.1 if end is None else min(0.1, max(0.0, end - loop.time())))
        return EXIT_OK

    return run_with_client("watch", args, body, role=Role.OBSERVER)
