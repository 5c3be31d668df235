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

from ..base.i18n import _
from ..client.console_effect import Effect
from ..client.why_values import Cause
from ..protocol.payloads.config import ParamType, Priority
from ._schema_names import COMMAND_SCHEMA, SCHEMA_NAMES

__all__ = ["COMMAND_SCHEMA", "SCHEMAS", "main"]

Schema = dict[str, Any]

NUMBER = {"type": "number"}
INTEGER = {"type": "integer"}
TEXT = {"type": "string"}
FLAG = {"type": "boolean"}
NUMBER_OR_NULL = {"type": ["number", "null"]}
INTEGER_OR_NULL = {"type": ["integer", "null"]}
TEXT_OR_NULL = {"type": ["string", "null"]}
ANY: Schema = {}


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


def constant(value: Any) -> Schema:
    return {"const": value}


def either(*values: Any) -> Schema:
    return {"enum": list(values)}


def or_null(schema: Schema) -> Schema:
    return {"oneOf": [schema, {"type": "null"}]}


STATUS = record(
    {"x": NUMBER, "y": NUMBER, "th": NUMBER, "vel": NUMBER, "rot_vel": NUMBER, "status": TEXT, "mode": TEXT},
    {"battery_v": NUMBER, "battery_pct": NUMBER, "dock": TEXT},
)
STATUS["oneOf"] = [{"required": ["battery_v"]}, {"required": ["battery_pct"]}]

WHY_ANSWER = record(
    {
        "can_move": FLAG,
        "cause": {"type": ["string", "null"]},
        "exit_code": INTEGER,
        "sentence": TEXT,
        "reasons": listing({"type": "object"}),
        "notes": listing(TEXT),
        "raw": listing({"type": "object"}),
    }
)
"""``rtmu why``'s answer (``client.why_values.Answer.as_json``), as ``rtmu drive`` adds it when the robot
did not move."""

POSE = {"x": NUMBER_OR_NULL, "y": NUMBER_OR_NULL, "th": NUMBER_OR_NULL}
SENT = record({"sent": TEXT})

# -- why won't it move? (rtmu why, and a drive that did not move) ----------------------------------
WHY_REASON = record(
    {
        "cause": either(*(c.key for c in Cause)),
        "exit_code": either(*(c.value for c in Cause)),
        "problem": TEXT,
        "advice": TEXT,
        "evidence": listing(TEXT),
        "loud": FLAG,
    },
    {"fix": record({"key": TEXT, "label": TEXT, "sends": TEXT, "confirm": FLAG})},
)
WHY_RAW = record({"name": TEXT, "description": TEXT, "hex": TEXT, "fields": listing(TEXT), "note": TEXT})
"""A reply RTMU shows as it came (an LD robot's safety data, whose layouts are not public)."""
WHY_ANSWER_KEYS: dict[str, Schema] = {
    "can_move": FLAG,
    "cause": {"enum": [None, *(c.key for c in Cause)]},
    "exit_code": either(0, *(c.value for c in Cause)),
    "sentence": TEXT,
    "reasons": listing(WHY_REASON),
    "notes": listing(TEXT),
    "raw": listing(WHY_RAW),
}
WHY_FIX_RESULT = record({"key": TEXT, "sent": FLAG, "worked": FLAG, "message": TEXT})

# -- the server's configuration (rtmu config and its care actions) -----------------------------------
CONFIG_PARAM = record(
    {
        "name": TEXT,
        "type": either(*(t.name.lower() for t in ParamType if t is not ParamType.SEPARATOR)),
        "value": {"type": ["boolean", "integer", "number", "string", "null"]},
        "description": TEXT,
        "priority": either(*(p.name.lower() for p in Priority)),
        "editable": FLAG,
    },
    {
        "min": NUMBER_OR_NULL,
        "max": NUMBER_OR_NULL,
        "choices": listing(TEXT),
        "restart": INTEGER,
        "members": listing({"$ref": "#/$defs/param"}),
    },
)
"""One parameter (``members``: a list parameter's own, each a parameter again)."""

# -- the console (rtmu call) ----------------------------------------------------------------------
CONSOLE_ENTRY = record(
    {
        "number": INTEGER,
        "name": TEXT,
        "description": TEXT,
        "arguments": TEXT,
        "returns": TEXT,
        "group": TEXT,
        "flags": TEXT,
        "effect": either(*(e.value for e in Effect)),
        "why": TEXT,
        "argument_layout": TEXT,
    }
)
CONSOLE_FIELD = record(
    {"kind": TEXT, "value": {"type": ["integer", "number", "string"]}, "offset": INTEGER}, {"label": TEXT}
)
CONSOLE_PACKET = record(
    {"size": INTEGER, "hex": TEXT, "fields": listing(CONSOLE_FIELD), "more_fields": INTEGER},
    {"typed": record({"type": TEXT, "fields": ANY, "error": TEXT_OR_NULL})},
)
CONSOLE_REPLY = record(
    {
        "name": TEXT,
        "outcome": either("replied", "taken", "sent", "silent", "stalled", "cut"),
        "packet_count": INTEGER,
        "bytes": INTEGER,
        "seconds": NUMBER,
        "packets": listing(CONSOLE_PACKET),
    },
    {"dropped": INTEGER},
)

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
        {"before": or_null(STATUS), "after": or_null(STATUS), "seconds": NUMBER},
        {"interrupted": TEXT, "moved": FLAG, "why": record(WHY_ANSWER_KEYS)},
    ),
    "why": record({"server": TEXT, **WHY_ANSWER_KEYS, "fixes": listing(WHY_FIX_RESULT)}),
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
    "config": {
        **one_of(
            record(
                {
                    "api": constant("arconfig"),
                    "source": TEXT,
                    "last_editable": either(*(p.name.lower() for p in Priority)),
                    "sections": listing(
                        record({"name": TEXT, "comment": TEXT, "params": listing({"$ref": "#/$defs/param"})})
                    ),
                }
            ),
            record({"api": TEXT, "data": listing(TEXT), "editable": constant(False)}),  # one RTMU cannot edit
            record({"accepted": FLAG, "error": TEXT}),  # --set
            record(  # --defaults
                {
                    "differences": listing(
                        record(
                            {"section": TEXT, "name": TEXT, "value": TEXT, "default": TEXT, "editable": FLAG}
                        )
                    ),
                    "factory_values": INTEGER,
                    "cut": INTEGER,
                }
            ),
            record({"reset": listing(TEXT), "accepted": FLAG, "error": TEXT}),  # --reset
            record({"exported": TEXT, "parameters": INTEGER}),  # --export
            record(  # --import: sent, or the problems that kept it from being sent
                {"accepted": FLAG, "sent": INTEGER},
                {"unchanged": INTEGER, "error": TEXT, "problems": listing(TEXT)},
            ),
            record({"reloaded": constant(True)}),  # --reload
        ),
        "$defs": {"param": CONFIG_PARAM},
    },
    "files": one_of(
        record(  # ls
            {
                "folder": TEXT,
                "source": TEXT,
                "entries": listing(
                    record(
                        {
                            "name": TEXT,
                            "type": either("folder", "file"),
                            "size": INTEGER,
                            "mtime": INTEGER,
                            "atime": INTEGER,
                        }
                    )
                ),
            }
        ),
        record(  # get
            {
                "remote": TEXT,
                "local": TEXT,
                "bytes": INTEGER,
                "seconds": NUMBER,
                "mtime": INTEGER_OR_NULL,
                "listed_size": INTEGER_OR_NULL,
            }
        ),
        record({"local": TEXT, "remote": TEXT, "bytes": INTEGER, "seconds": NUMBER}),  # put
        record({"deleted": TEXT}),  # rm
    ),
    "scan": one_of(
        record({"scanning": constant(True), "file": TEXT}),  # start
        record({"scanning": FLAG, "name": TEXT, "file": TEXT}),  # status
        record({"loop": either("start", "end"), "tag": TEXT, "taken": FLAG}),  # loop
        record({"stopped": constant(True), "file": TEXT}, {"downloaded": TEXT, "bytes": INTEGER}),  # stop
    ),
    "mapedit": one_of(
        record({"map_updated": FLAG}),  # --check-map
        record(
            {
                "removed": listing(TEXT),
                "added": listing(TEXT),
                "applied": {"type": ["boolean", "null"]},
                "status": INTEGER_OR_NULL,
                "words": TEXT,
                "map_updated": FLAG,
                "holds": FLAG,
                "missing": listing(TEXT),
            }
        ),
    ),
    "call": one_of(listing(CONSOLE_ENTRY), CONSOLE_REPLY),  # --list (one array), or one object per reply
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

if tuple(SCHEMAS) != SCHEMA_NAMES:  # the command line's names (``_schema_names``) are these, in order
    raise ImportError(f"_schema_names.SCHEMA_NAMES is not SCHEMAS' names: {tuple(SCHEMAS)}")


def main(argv: list[str]) -> int:
    if len(argv) != 1 or argv[0] not in SCHEMAS:
        print(
            _("usage: python -m rtmu.subcommands.json_schemas {{{join}}}").format(
                join=",".join(sorted(SCHEMAS))
            ),
            file=sys.stderr,
        )
        return 2
    print(
        json.dumps({"$schema": "https://json-schema.org/draft/2020-12/schema", **SCHEMAS[argv[0]]}, indent=2)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
