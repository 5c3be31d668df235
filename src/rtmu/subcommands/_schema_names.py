"""Which published schema each command's ``--json`` lines follow: names only.

A command's help names its schema; the schemas themselves (:mod:`.json_schemas`, one per name in
:data:`SCHEMA_NAMES`) import the values they describe — a third of a command's start-up — so the
command line reads the names here.
"""

from __future__ import annotations

SCHEMA_NAMES = (
    "status", "navigate", "localize", "drive", "why", "goals", "routes", "probe", "commands", "config",
    "files", "scan", "mapedit", "call", "drawings", "watch", "ptz", "video", "run", "fleet", "doctor",
)  # fmt: skip
"""Every published schema, in :data:`.json_schemas.SCHEMAS`' order (which checks it)."""
NAVIGATING = ("goto", "home", "dock")
"""Commands that print a navigation's lines (schema ``navigate``)."""
COMMAND_SCHEMA = {
    **{name: "navigate" for name in NAVIGATING},
    **{name: name for name in SCHEMA_NAMES if name != "navigate"},
}
"""Subcommand → the schema of its ``--json`` lines."""
