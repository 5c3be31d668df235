"""A named JSON schema for every JSON channel, so Foxglove names what it shows (``rtmu.Status`` …).

Without one, foxglove-sdk names every schemaless JSON channel after a hash of the empty schema,
and all of them come out as the same ``schema-f5wrpOiP``. Recordings (:mod:`.mcapfile`) and the
live bridge (:mod:`.bridge`) take the schema of a topic from here, so both say the same. The
schemas describe the fields RTMU writes and allow more (``additionalProperties``), so a field added
later keeps older files valid.
"""

from __future__ import annotations

import json
from functools import cache
from typing import Any

from ..capture.recorded import CONNECTION_TOPIC
from . import topics

ENCODING = "jsonschema"
"""The schema encoding of a JSON channel (MCAP's and the Foxglove WebSocket protocol's word)."""

_NUMBER = {"type": ["number", "null"]}
_INT = {"type": ["integer", "null"]}
_TEXT = {"type": "string"}
_FLAG = {"type": ["boolean", "null"]}


def _object(title: str, description: str, **properties: Any) -> dict[str, Any]:
    return {
        "title": title,
        "description": description,
        "type": "object",
        "properties": properties,
        "additionalProperties": True,
    }


_SCHEMAS: dict[str, dict[str, Any]] = {
    topics.STATUS: _object(
        "rtmu.Status",
        "The robot's status as its server reports it (updateNumbers/updateStrings, batteryInfo, …).",
        mode=_TEXT,
        mode_name=_TEXT,
        status=_TEXT,
        extended_status=_TEXT,
        battery=_object(
            "rtmu.Battery",
            "volts or state_of_charge_pct, whichever the robot reports; neither until it is known",
            state={"enum": ["ok", "low", "critical", "unknown"]},
            volts=_NUMBER,
            state_of_charge_pct=_NUMBER,
            low=_NUMBER,
            shutdown=_NUMBER,
        ),
        vel_mm_s=_NUMBER,
        rot_vel_deg_s=_NUMBER,
        lat_vel_mm_s=_NUMBER,
        moving=_FLAG,
        temperature_c={**_NUMBER, "description": "null: the robot reports none"},
        safe_drive=_FLAG,
        dock_state={"type": ["string", "null"]},
        wifi_quality=_INT,
        wifi_signal=_INT,
        closest_obstacle_mm=_INT,
    ),
    topics.CONNECTION: _object(
        "rtmu.Connection",
        "The link to the robot's server: its phase and, when it failed, why.",
        phase=_TEXT,
        host=_TEXT,
        port=_INT,
        user=_TEXT,
        error=_TEXT,
        error_kind=_TEXT,
        attempt=_INT,
        retry_in=_NUMBER,
    ),
    topics.LINK_HEALTH: _object(
        "rtmu.LinkHealth",
        "How well the link works: level, round trip, drops, unanswered pings.",
        level=_TEXT,
        rtt_ms=_NUMBER,
        dropped=_INT,
        garbage_bytes=_INT,
        ping_failures=_INT,
    ),
    topics.MAP_STATE: _object(
        "rtmu.MapState",
        "The map download: phase, map name, generation, error.",
        state=_TEXT,
        name=_TEXT,
        generation=_INT,
        error=_TEXT,
    ),
    topics.NAVIGATION: _object(
        "rtmu.Navigation",
        "What an ARNL-class server is doing on its own: goal, path, outcome, localization.",
        navigating=_FLAG,
        target=_TEXT,
        outcome=_TEXT,
        outcome_text=_TEXT,
        reason=_TEXT,
        remaining_mm=_NUMBER,
        loc_state={"type": ["string", "null"]},
        loc_score={**_NUMBER, "description": "0–1 (an LD robot's 0–100 scaled); null when not offered"},
    ),
    topics.NOTICES: _object(
        "rtmu.Notice", "A message shown to the operator.", kind=_TEXT, level=_TEXT, text=_TEXT
    ),
    topics.INTENTS: _object("rtmu.Intent", "What the operator asked for (never a password).", intent=_TEXT),
    topics.LEASE: _object(
        "rtmu.LeaseEvent",
        "A drive lease granted, changed or ended (with why).",
        event=_TEXT,
        generation=_INT,
        ratios={"type": "object"},
        reason={"type": ["string", "null"]},
    ),
    topics.STOPS: _object(
        "rtmu.Stop",
        "Zero ratios + stop sent by the client or the guardian, with why.",
        by=_TEXT,
        reason=_TEXT,
        sent=_FLAG,
    ),
    topics.RECORDER: _object("rtmu.RecorderEvent", "The recorder's own events.", event=_TEXT, items=_INT),
    CONNECTION_TOPIC: _object(
        "rtmu.RawConnection",
        "The raw ArNetworking chunks after this message belong to connection conn.",
        conn=_INT,
        host=_TEXT,
        port=_INT,
    ),
}


def _camel(words: str) -> str:
    return "".join(part[:1].upper() + part[1:] for part in words.replace("-", "_").split("_") if part)


def schema_name(topic: str) -> str:
    """``rtmu.Status`` for ``/robot/status``; ``rtmu.values.state.Popups`` for ``/rtmu/state/popups`` …"""
    known = _SCHEMAS.get(topic)
    if known is not None:
        return str(known["title"])
    if topic.startswith(topics.STATE_PREFIX):
        return "rtmu.values.state." + _camel(topic.removeprefix(topics.STATE_PREFIX))
    return "rtmu." + _camel(topic.rstrip("/").rsplit("/", 1)[-1] or "Message")


@cache
def schema_data(topic: str) -> bytes:
    """The JSON schema of a JSON topic, as the bytes a channel carries."""
    schema = _SCHEMAS.get(topic)
    if schema is None:
        schema = _object(schema_name(topic), f"RTMU's JSON messages on {topic}.")
    return json.dumps(schema, separators=(",", ":")).encode()
