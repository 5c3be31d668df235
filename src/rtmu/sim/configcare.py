"""Configuration care in the simulator (a data module): factory values, one-parameter sets, reload.

``getConfigDefaults`` answers the values every parameter had when the simulator started, in ONE packet
of ``setConfig`` pairs as ARIA's handler does (a section asked for by name alone; an oversized answer is
cut at the last whole pair that fits, where ARIA's packet would just stop filling). ``setConfigParam``
goes through the same all-or-nothing validation as ``setConfig`` and answers the last section named and
the first error. ``reloadConfig`` reads "the file" again — the simulator keeps its file in memory, and
ARIA writes the file after every accepted set, so nothing changes — and broadcasts ``configUpdated``
to every client, the asker too, as ARIA does; it sends no reply.
"""

from __future__ import annotations

from collections.abc import Iterable

from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads.config import SECTION_TAG, ConfigUpdated
from rtmu.protocol.payloads.configcare import (
    ConfigDefaults,
    ConfigDefaultsRequest,
    SetConfigParam,
    SetConfigParamReply,
)

from .catalogue import Row
from .handlers import Call, Handler, Reply


def defaults_pairs(defaults: list[tuple[str, str, str]], section: str = "") -> tuple[tuple[str, str], ...]:
    """The factory values as ``getConfigDefaults`` pairs, cut to what fits in one packet."""
    pairs: list[tuple[str, str]] = []
    size = 0
    current = None
    for sec, name, value in defaults:
        if section and sec.lower() != section.lower():
            continue
        add = [(SECTION_TAG, sec)] if sec != current else []
        add.append((name, value))
        grow = sum(len(a) + len(b) + 2 for a, b in add)
        if size + grow > MAX_PAYLOAD:
            break
        pairs += add
        size += grow
        current = sec
    return tuple(pairs)


def _defaults(call: Call) -> Iterable[Reply]:
    try:
        section = ConfigDefaultsRequest.decode(call.args).section
    except ProtocolError:
        section = ""
    return (ConfigDefaults(defaults_pairs(call.server.arconfig.defaults, section)).encode(),)


def _set_param(call: Call) -> Iterable[Reply]:
    try:
        request = SetConfigParam.decode(call.args)
    except ProtocolError as exc:
        return (SetConfigParamReply("", f"the request did not decode: {exc}").encode(),)
    error, changed = call.server.arconfig.apply(request)
    last = next((value for name, value in reversed(request.pairs) if name.lower() == SECTION_TAG.lower()), "")
    if changed:
        call.server.broadcast(ConfigUpdated.DATA_NAME, ConfigUpdated().encode(), exclude=call.session)
    return (SetConfigParamReply(last, error).encode(),)


def _reload(call: Call) -> Iterable[Reply]:
    call.server.broadcast(ConfigUpdated.DATA_NAME, ConfigUpdated().encode())
    return ()


def _broadcast_only(call: Call) -> Iterable[Reply]:
    return ()


ROWS: tuple[Row, ...] = (
    # serverDemo lists these two with these texts (shared/captures/clientCommandLister-serverDemoMap.pcap).
    (
        "setConfigParam",
        "Sets the value of a single configuration parameter",
        "TODO",
        "string: empty if successful, otherwise the first error that occurred",
        "ConfigEditing",
        "RETURN_SINGLE|IDLE_PACKET",
    ),
    (
        "reloadConfig",
        "reloads the configuration file last loaded",
        "none",
        "none",
        "ConfigEditing",
        "RETURN_SINGLE|IDLE_PACKET",
    ),
    # Offered by ARIA only with a defaults file; no capture has them, so the texts are our own.
    (
        "getConfigDefaults",
        "The factory value of every configuration parameter",
        "string: one section's name, or empty for all of them",
        "pairs of strings: Section and its name, then each parameter and its value",
        "ConfigEditing",
        "RETURN_SINGLE",
    ),
    (
        "configDefaultsUpdated",
        "Sent when the factory values are read again",
        "none",
        "none",
        "ConfigEditing",
        "RETURN_SINGLE",
    ),
)

PLACE_AFTER = {"setConfigParam": "setConfig", "reloadConfig": "setConfigParam"}
"""serverDemo's order (the set-by-sections data between them are not served)."""

HANDLERS: dict[str, Handler] = {
    "getConfigDefaults": _defaults,
    "configDefaultsUpdated": _broadcast_only,
    "setConfigParam": _set_param,
    "reloadConfig": _reload,
}
