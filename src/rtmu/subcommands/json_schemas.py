"""The published shape of every ``--json`` line, as JSON Schema (draft 2020-12): what scripts may rely on.

``SCHEMAS[name]`` validates one line (one JSON value) of a command's ``--json`` output; a command
that prints several kinds of line has a schema that is one of them. ``rtmu NAME --help`` names its
schema; ``python -m rtmu.subcommands.json_schemas NAME`` prints it. ``tests/test_json_schemas.py``
runs each command against the simulator and checks every line it prints.
"""

from __future__ import annotations

import json
import sys
from typing import Any

Schema = dict[str, Any]

NUMBER = {"type": "number"}
INTEGER = {"type": "integer"}
TEXT = {"type": "string"}
FLAG = {"type": "boolean"}
NUMBER_OR_NULL = {"type": ["number", "null"]}


def record(
    required: dict[str, Any], optional: dict[str, Any] | None = None, *, closed: bool = True
) -> Schema:
    """An object with these keys (``closed``: and no others)."""
    properties = {**required, **(optional or {})}
    return {
        "type": "object",
        "required": sorted(required),
        "properties": properties,
        "additionalProperties": not closed,
    }


def one_of(*schemas: Schema) -> Schema:
    return {"oneOf": list(schemas)}


def listing(item: Schema) -> Schema:
    return {"type": "array", "items": item}


STATUS = record(
    {"x": NUMBER, "y": NUMBER, "th": NUMBER, "vel": NUMBER, "rot_vel": NUMBER, "status": TEXT, "mode": TEXT},
    {"battery_v": NUMBER, "battery_pct": NUMBER, "dock": TEXT},
)
STATUS["oneOf"] = [{"required": ["battery_v"]}, {"required": ["battery_pct"]}]

POSE = {"x": NUMBER_OR_NULL, "y": NUMBER_OR_NULL, "th": NUMBER_OR_NULL}
SENT = record({"sent": TEXT})

SCHEMAS: dict[str, Schema] = {
    "status": STATUS,
    "navigate": one_of(
        record({"status": TEXT, "phase": TEXT}),
        record({"remaining_mm": INTEGER}),
        record(
            {
                "outcome": {"enum": ["arrived", "docked", "failed", "cancelled", "timeout", "interrupted"]},
                **POSE,
            },
            {"text": TEXT, "reason": TEXT, "signal": TEXT},
        ),
        SENT,
    ),
    "localize": one_of(
        record({"localization": TEXT}),
        record({"outcome": {"enum": ["localized", "lost", "timeout"]}}, {"score": NUMBER}),
        SENT,
    ),
    "drive": record(
        {"before": STATUS, "after": {"oneOf": [STATUS, {"type": "null"}]}, "seconds": NUMBER},
        {"interrupted": TEXT},
    ),
    "goals": listing(TEXT),
    "routes": listing(TEXT),
    "probe": record(
        {
            "server": TEXT,
            "user": TEXT,
            "count": INTEGER,
            "data": listing(
                record(
                    {"number": INTEGER, "name": TEXT, "group": TEXT, "flags": listing(TEXT)},
                    {"description": TEXT, "arguments": TEXT, "returns": TEXT},
                )
            ),
        }
    ),
    "commands": listing(record({"name": TEXT, "description": TEXT, "argument": FLAG}, closed=False)),
    "config": one_of(
        record(
            {
                "source": TEXT,
                "sections": listing(
                    record({"name": TEXT, "params": listing({"type": "object"})}, closed=False)
                ),
            },
            closed=False,
        ),
        record({"accepted": FLAG}, {"error": TEXT}, closed=False),
    ),
    "drawings": listing(
        record({"name": TEXT, "shape": TEXT, "drawn": FLAG, "points": listing(listing(NUMBER))}, closed=False)
    ),
    "watch": record({"t": NUMBER, "event": TEXT}, closed=False),
    "ptz": record(
        {
            "cameras": listing(
                record({"name": TEXT, "type": TEXT, "display_name": TEXT, "commands": listing(TEXT)})
            ),
            "ptz": {"oneOf": [{"type": "null"}, record({"camera": TEXT}, closed=False)]},
            "reason": TEXT,
        }
    ),
    "video": record(
        {
            "source": TEXT,
            "seconds": NUMBER,
            "frames": INTEGER,
            "fps": NUMBER,
            "kbps": NUMBER,
            "width": INTEGER,
            "height": INTEGER,
            "age_ms_p50": NUMBER_OR_NULL,
            "age_ms_p95": NUMBER_OR_NULL,
            "client_ms_p95": NUMBER_OR_NULL,
            "repeats": INTEGER,
            "dropped": INTEGER,
            "skipped": INTEGER,
            "target_fps": NUMBER,
            "rate_fps": NUMBER,
            "backoff": TEXT,
            "notes": listing(TEXT),
        },
        {"camera_fps": NUMBER_OR_NULL, "new_frames": INTEGER},
    ),
    "run": record({"command": TEXT, "argument": {"type": ["string", "null"]}, "taken": FLAG}),
    "fleet": record(
        {
            "central": TEXT,
            "robots": listing(
                record(
                    {"name": TEXT, "host": TEXT, "port": INTEGER, "address": TEXT},
                    {"status": {"oneOf": [STATUS, record({"error": TEXT})]}},
                )
            ),
        }
    ),
    "doctor": record(
        {
            "server": TEXT,
            "ok": FLAG,
            "failed_step": {"type": ["string", "null"]},
            "exit_code": INTEGER,
            "features": {"type": "object", "additionalProperties": FLAG},
            "steps": listing(
                record(
                    {"step": TEXT, "title": TEXT, "result": TEXT, "summary": TEXT, "advice": TEXT},
                    closed=False,
                )
            ),
        }
    ),
}
"""Schema name → the JSON Schema of one ``--json`` line (the navigation commands share ``navigate``)."""

COMMAND_SCHEMA = {
    "goto": "navigate",
    "home": "navigate",
    "dock": "navigate",
    **{name: name for name in SCHEMAS if name != "navigate"},
}
"""Subcommand → the schema of its ``--json`` lines."""


def main(argv: list[str]) -> int:
    if len(argv) != 1 or argv[0] not in SCHEMAS:
        print(
            f"usage: python -m rtmu.subcommands.json_schemas {{{','.join(sorted(SCHEMAS))}}}", file=sys.stderr
        )
        return 2
    print(
        json.dumps({"$schema": "https://json-schema.org/draft/2020-12/schema", **SCHEMAS[argv[0]]}, indent=2)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
