"""The console's words: a data of the list and a reply, as plain lines — one wording for ``rtmu call``
and the window's console page.

Every text that came from the server goes through :func:`~rtmu.base.textsafe.visible` (control and
format characters escaped), so neither a terminal nor a label can be steered by it. Lengths are
already bounded by the model (:mod:`~rtmu.client.console_reply`: 16 packets, 200 fields a packet,
the first bytes as hex); long descriptions are shortened here.
"""

from __future__ import annotations

import json

from ..base.textsafe import visible
from .console import ConsoleEntry, ConsoleReply
from .console_layout import describe

SILENT_OUTCOMES = ("silent", "stalled", "sent")
"""Outcomes that mean no (whole) answer: ``rtmu call`` exits 5 on them."""


def short(text: str, limit: int = 160) -> str:
    """``text`` on one line, cut at ``limit`` characters (an ellipsis says it was)."""
    one = " ".join(text.split())
    return one if len(one) <= limit else one[: limit - 1] + "…"


def effect_words(entry: ConsoleEntry) -> str:
    return f"changes something ({entry.why})" if entry.changes else "read"


def entry_lines(entry: ConsoleEntry) -> list[str]:
    """A data of the list: number, name, group, flags and effect; its description; its layouts."""
    d = entry.data
    group = f"[{visible(d.command_group)}] {visible(d.flags)}"
    lines = [f"{d.number:5d}  {visible(d.name)}  {group}  {effect_words(entry)}"]
    if d.description:
        lines.append(f"       {visible(d.description)}")
    returns = visible(short(d.return_description))
    lines.append(f"       arguments: {visible(describe(entry.arguments))}   returns: {returns}")
    return lines


def outcome_line(reply: ConsoleReply, timeout: float) -> str:
    """One line: the data, how the call ended, what came back."""
    packets = f"{reply.packet_count} packet{'s' if reply.packet_count != 1 else ''}"
    what = {
        "replied": f"{packets}, {reply.byte_count} bytes",
        "cut": f"{reply.packet_count} packets, {reply.byte_count} bytes (stopped reading there)",
        "taken": "no reply by design; the server took it",
        "sent": f"no reply by design; the server did not confirm taking it within {timeout:g} s",
        "silent": f"no reply within {timeout:g} s",
        "stalled": f"{reply.packet_count} packets, then nothing for {timeout:g} s",
    }.get(reply.outcome, reply.outcome)
    dropped = f" ({reply.dropped} older replies dropped)" if reply.dropped else ""
    return f"{visible(reply.name)}: {reply.outcome}: {what}{dropped}"


def packet_lines(reply: ConsoleReply) -> list[str]:
    """Each packet kept: its bytes as hex, its fields, and RTMU's own type where it has one."""
    lines: list[str] = []
    for index, packet in enumerate(reply.packets, 1):
        lines.append(f"  packet {index} ({packet.size} bytes): {packet.hex}")
        for f in packet.fields:
            label = f"  ({visible(f.label)})" if f.label else ""
            value = visible(json.dumps(f.value, ensure_ascii=False)) if isinstance(f.value, str) else f.value
            lines.append(f"    {f.kind} {value}{label}")
        if packet.more_fields:
            lines.append(f"    … and {packet.more_fields} more fields")
        if packet.typed_name:
            typed = packet.typed_error or json.dumps(packet.typed, ensure_ascii=False, separators=(",", ":"))
            lines.append(f"    as {packet.typed_name}: {visible(typed)}")
    if reply.packet_count > len(reply.packets):
        lines.append(f"  (+{reply.packet_count - len(reply.packets)} more packets not shown)")
    return lines
