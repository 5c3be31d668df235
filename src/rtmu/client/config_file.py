"""A server's configuration as a file: export it, check a file against a server, import it all or nothing.

The file is TOML (UTF-8), one table per section, every value a string in the form ``setConfig`` sends
it (ARIA's own text: ``true``/``false``, ``2``, ``0.5``, ``320x240``)::

    # rtmu configuration export
    format = "rtmu-config-1"
    server = "robot.local:7272"

    ["Teleop"]
    "Timeout" = "2"
    ["Robot config"]
    "SerialNumber" = "SIM-P3DX-0001"  # factory, read-only

Importing checks the whole file against the server's own description before anything is sent: every
section and parameter must exist, a value must fit its type and limits, and a read-only parameter may
only hold the value it has. Values equal to the current ones are left out; the rest go in ONE
``setConfig``, which the server also takes all or nothing. A file that already exists is never
overwritten unless asked; the export goes to a temporary file renamed into place.
"""

from __future__ import annotations

import json
import os
import secrets
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..protocol.payloads.config import ConfigParam, ParamType, Priority
from .config_care import same_value
from .config_feed import MAX_PARAMS, ServerConfig, check_value

FORMAT = "rtmu-config-1"
MAX_FILE_BYTES = 16 << 20
HEADER_KEYS = ("format", "server", "source")


class ConfigFileError(ValueError):
    """A configuration file that cannot be written, read or imported, and why."""


def _q(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's; non-ASCII as ``\\uXXXX``)."""
    return json.dumps(text, ensure_ascii=True)


def valued(config: ServerConfig) -> list[tuple[str, ConfigParam]]:
    """``(section, parameter)`` of every parameter that has a value of its own (not lists, separators)."""
    return [
        (s.name, p)
        for s in config.sections
        for p in s.params
        if p.kind not in (ParamType.SEPARATOR, ParamType.LIST)
    ]


def export_text(config: ServerConfig, server: str = "") -> str:
    lines = [
        "# rtmu configuration export: every parameter's value as the server's setConfig takes it.",
        "# Import with: rtmu config HOST --import FILE (checked first; all or nothing).",
        f"format = {_q(FORMAT)}",
        f"server = {_q(server)}",
        f"source = {_q(config.source)}",
    ]
    grouped: dict[str, dict[str, ConfigParam]] = {}
    for name, param in valued(config):  # one table per section, one key per name: what TOML allows
        grouped.setdefault(name, {}).setdefault(param.name, param)
    for name, params in grouped.items():
        lines += ["", f"[{_q(name)}]"]
        for p in params.values():
            note = "" if config.editable(p) else f"  # {Priority.of(p.priority).name.lower()}, read-only"
            lines.append(f"{_q(p.name)} = {_q(p.value_text())}{note}")
    return "\n".join(lines) + "\n"


def write_export(path: Path, text: str, *, force: bool = False) -> None:
    """Write ``text`` to ``path`` whole or not at all; an existing file is kept unless ``force``."""
    if path.exists() and not force:
        raise ConfigFileError(f"{path} already exists (give --force to replace it)")
    temp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
    try:
        with open(temp, "x", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if force:
            os.replace(temp, path)
        else:
            os.link(temp, path)  # fails if the file appeared meanwhile: never overwritten unasked
    except FileExistsError:
        raise ConfigFileError(f"{path} already exists (give --force to replace it)") from None
    except OSError as exc:
        raise ConfigFileError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        temp.unlink(missing_ok=True)


def read_file(path: Path) -> dict[str, dict[str, str]]:
    """``{section: {parameter: value}}`` from an export file; ConfigFileError saying what is wrong."""
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ConfigFileError(f"cannot read {path}: {exc.strerror or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ConfigFileError(f"{path} is larger than {MAX_FILE_BYTES >> 20} MB: not a configuration export")
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ConfigFileError(f"{path} is not a configuration export: {exc}") from None
    if doc.get("format") != FORMAT:
        raise ConfigFileError(f'{path} is not a configuration export (no format = "{FORMAT}")')
    out: dict[str, dict[str, str]] = {}
    count = 0
    for key, table in doc.items():
        if key in HEADER_KEYS:
            continue
        if not isinstance(table, dict):
            raise ConfigFileError(f"{path}: {key!r} is not a section (a [table] of parameters)")
        for name, value in table.items():
            if not isinstance(value, str):
                raise ConfigFileError(
                    f"{path}: [{key}] {name!r} must be a string, as the server writes values"
                )
            count += 1
            if count > MAX_PARAMS:
                raise ConfigFileError(f"{path} holds more than {MAX_PARAMS} parameters")
            out.setdefault(key, {})[name] = value
    return out


@dataclass(frozen=True, slots=True)
class ImportPlan:
    """What an import would send, or why it cannot."""

    changes: dict[str, dict[str, str]]
    """``{section: {parameter: value}}`` with the server's own spelling of the names."""
    unchanged: int
    problems: tuple[str, ...]


def plan_import(config: ServerConfig, values: dict[str, dict[str, str]]) -> ImportPlan:
    """Check every value against ``config``; the changes to send, or every problem found."""
    sections = {s.name.lower(): s for s in config.sections}
    changes: dict[str, dict[str, str]] = {}
    problems: list[str] = []
    unchanged = 0
    for sec_name, params in values.items():
        section = sections.get(sec_name.lower())
        if section is None:
            problems.append(f"no section {sec_name!r} on this server")
            continue
        by_name = {
            p.name.lower(): p for p in section.params if p.kind not in (ParamType.SEPARATOR, ParamType.LIST)
        }
        for name, value in params.items():
            param = by_name.get(name.lower())
            where = f"{section.name}/{name}"
            if param is None:
                problems.append(f"no parameter {where} on this server")
                continue
            if same_value(param, value):
                unchanged += 1
                continue
            if not config.editable(param):
                problems.append(f"{where} is read-only here ({value!r} differs from {param.value_text()!r})")
                continue
            why = check_value(param, value)
            if why:
                problems.append(f"{where}: {value!r} is {why}")
                continue
            changes.setdefault(section.name, {})[param.name] = value
    return ImportPlan(changes, unchanged, tuple(problems))
