"""The server's catalogue of data (protocol §2.7–2.8): name ↔ number, descriptions, group, flags.

Servers number their data differently, so everything above the codec looks
data up by name here. The same object builds the three list packets on the
server side and absorbs them on the client side.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

from .commands import FIRST_DATA_NUMBER, ServerCommand
from .errors import PayloadError
from .fields import FieldReader, FieldWriter
from .packet import MAX_PAYLOAD, Packet


@dataclass(frozen=True, slots=True)
class DataEntry:
    number: int
    name: str
    description: str = ""
    argument_description: str = ""
    return_description: str = ""
    command_group: str = ""
    flags: str = ""

    @property
    def flag_set(self) -> frozenset[str]:
        return frozenset(f for f in self.flags.split("|") if f)


class DataList:
    """Name ↔ number lookup with everything the server said about each data."""

    def __init__(self, entries: Iterable[DataEntry] = ()) -> None:
        self._by_number: dict[int, DataEntry] = {}
        self._by_name: dict[str, DataEntry] = {}
        self.names: dict[int, str] = {}
        """Number → name (read only): ``names.get`` is the per-packet lookup, one C call."""
        self.have_list = False
        self.have_argret = False
        self.have_groups = False
        for entry in entries:
            self.add(entry)

    # -- lookup ---------------------------------------------------------
    def add(self, entry: DataEntry) -> None:
        old = self._by_number.get(entry.number)
        if old is not None and self._by_name.get(old.name) is old:
            del self._by_name[old.name]
        self._by_number[entry.number] = entry
        self._by_name[entry.name] = entry
        self.names[entry.number] = entry.name

    def __contains__(self, name: object) -> bool:
        return name in self._by_name

    def __iter__(self) -> Iterator[DataEntry]:
        return iter(sorted(self._by_number.values(), key=lambda e: e.number))

    def __len__(self) -> int:
        return len(self._by_number)

    def number(self, name: str) -> int | None:
        entry = self._by_name.get(name)
        return entry.number if entry else None

    def name(self, number: int) -> str | None:
        entry = self._by_number.get(number)
        return entry.name if entry else None

    def entry(self, name_or_number: str | int) -> DataEntry | None:
        if isinstance(name_or_number, int):
            return self._by_number.get(name_or_number)
        return self._by_name.get(name_or_number)

    @property
    def complete(self) -> bool:
        """True once LISTGROUPANDFLAGS arrived: ARIA sends no other end marker."""
        return self.have_list and self.have_groups

    # -- client side: absorb list packets --------------------------------
    def absorb(self, packet: Packet) -> bool:
        """Take in one list packet; False if ``packet`` is not a list packet."""
        cmd = packet.command
        if cmd in (ServerCommand.LIST, ServerCommand.LISTSINGLE):
            for number, name, desc in _triples(packet, cmd == ServerCommand.LIST):
                old = self._by_number.get(number)
                self.add(replace(old, name=name, description=desc) if old else DataEntry(number, name, desc))
            self.have_list = True
            return True
        if cmd in (ServerCommand.LISTARGRET, ServerCommand.LISTARGRETSINGLE):
            for number, arg, ret in _triples(packet, cmd == ServerCommand.LISTARGRET):
                self._amend(number, argument_description=arg, return_description=ret)
            self.have_argret = True
            return True
        if cmd in (ServerCommand.LISTGROUPANDFLAGS, ServerCommand.LISTGROUPANDFLAGSSINGLE):
            for number, group, flags in _triples(packet, cmd == ServerCommand.LISTGROUPANDFLAGS):
                self._amend(number, command_group=group, flags=flags)
            self.have_groups = True
            return True
        return False

    def _amend(self, number: int, **changes: str) -> None:
        old = self._by_number.get(number)
        # ARIA's client stops at an unknown number; we keep what we know and skip it.
        if old is not None:
            self.add(replace(old, **changes))  # type: ignore[arg-type]  # only the str fields are amended

    # -- server side: build list packets ----------------------------------
    def list_packets(self) -> list[Packet]:
        """LIST, one or more LISTARGRET, LISTGROUPANDFLAGS, as ARIA's server sends them."""
        entries = list(self)
        out: list[Packet] = []
        out.extend(_pack(ServerCommand.LIST, [(e.number, e.name, e.description) for e in entries]))
        out.extend(
            _pack(
                ServerCommand.LISTARGRET,
                [(e.number, e.argument_description, e.return_description) for e in entries],
            )
        )
        out.extend(
            _pack(ServerCommand.LISTGROUPANDFLAGS, [(e.number, e.command_group, e.flags) for e in entries])
        )
        return out

    def visible_to(self, groups: Iterable[str] | None) -> DataList:
        """The entries a user with ``groups`` may see (None or ``all`` = everything)."""
        if groups is None:
            return self
        allowed = {g.lower() for g in groups}
        if "all" in allowed:
            return self
        return DataList(e for e in self if not e.command_group or e.command_group.lower() in allowed)

    @classmethod
    def build(cls, specs: Iterable[tuple[str, str, str, str, str, str]]) -> DataList:
        """Number ``(name, description, args, returns, group, flags)`` rows from 256, as ``addData`` does."""
        return cls(DataEntry(FIRST_DATA_NUMBER + i, *spec) for i, spec in enumerate(specs))


def _triples(packet: Packet, counted: bool) -> Iterator[tuple[int, str, str]]:
    reader = FieldReader(packet.payload)
    count = reader.ubyte2("count", default=0) if counted else 1  # ARIA reads a missing count as 0
    if count * 4 > reader.remaining + 4 * 3:
        raise PayloadError(f"list packet claims {count} entries in {len(packet.payload)} bytes")
    for _ in range(count):
        # ARIA's writer silently drops entries, or single fields, that do not fit in the packet: take
        # what is there, with a missing text read as "" as ARIA's own reader does.
        if reader.remaining < 2:
            return
        yield (
            reader.ubyte2("data number"),
            reader.string("first text", default=""),
            reader.string("second text", default=""),
        )


def _pack(command: int, rows: list[tuple[int, str, str]]) -> list[Packet]:
    """Split rows over as many packets as needed, each under the payload limit with its own count."""
    packets: list[Packet] = []
    chunk: list[bytes] = []
    size = 2
    for number, a, b in rows:
        row = FieldWriter().ubyte2(number).string(a).string(b).bytes()
        if chunk and size + len(row) > MAX_PAYLOAD:
            packets.append(Packet(command, FieldWriter().ubyte2(len(chunk)).bytes() + b"".join(chunk)))
            chunk, size = [], 2
        chunk.append(row)
        size += len(row)
    packets.append(Packet(command, FieldWriter().ubyte2(len(chunk)).bytes() + b"".join(chunk)))
    return packets
