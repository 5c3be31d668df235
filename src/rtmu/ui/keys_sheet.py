"""What the keys window lists: the one key table (``keys.bindings()``) as rows of words and key caps,
in groups, filtered as the operator types (GTK-free: the rules are tested without a display).

One row per action: a binding's keys all appear (keypad twins too), so the window never lists a key
the window does not bind nor misses one it binds. Bindings with the same heading and words are one
row (Alt+1 … Alt+9 select a robot each), drawn as a run from the first key to the last when their keys
differ only by a digit counting up. Every word is translated when the sheet is made — the language the
window opened in — and key names too (``Ctrl`` is ``Strg`` on a German keyboard); a letter or a sign is
printed as on the key.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..base.i18n import N_, _, ngettext

GROUP_ORDER = (
    N_("STOP"),
    N_("Driving"),
    N_("Moves"),
    N_("Speed"),
    N_("Navigation"),
    N_("Map"),
    N_("Camera head"),
    N_("Window"),
    N_("Fleet"),
    N_("Connection"),
    N_("Robot"),
    N_("Application"),
)
"""The order of the groups: what stops the robot first, then what moves it. Groups not named here
come last, in the table's order."""

MODIFIERS = {
    "control": N_("Ctrl"),
    "primary": N_("Ctrl"),
    "shift": N_("Shift"),
    "alt": N_("Alt"),
}
"""GTK accelerator modifiers (``<Control>``) as the key cap says them."""

KEY_WORDS = {
    "space": N_("Space"),
    "Escape": N_("Esc"),
    "Page_Up": N_("Page Up"),
    "Page_Down": N_("Page Down"),
    "Menu": N_("Menu"),
}
"""Keys whose cap carries a word: translated. (Only the table's: a key added to it with a word of its
own — Home, whose word is also the robot's home — gets its name as GTK spells it until it is added.)"""

KEY_SIGNS = {
    "Up": "↑",
    "Down": "↓",
    "Left": "←",
    "Right": "→",
    "plus": "+",
    "minus": "-",
    "equal": "=",
    "comma": ",",
    "period": ".",
    "question": "?",
    "slash": "/",
}
"""Keys whose cap carries a sign, the same in every language."""

KEYPAD = N_("Keypad {key}")
"""A key of the numeric keypad (``KP_5``, ``KP_Add``): the keypad's twin of a key."""

KEYPAD_SIGNS = {"Add": "+", "Subtract": "-", "Multiply": "*", "Divide": "/"}

_ACCEL = re.compile(r"<([A-Za-z0-9]+)>")


class KeyEntry(Protocol):
    """What the sheet reads of a binding (``keys.Binding``): its keys, words and heading."""

    @property
    def accels(self) -> tuple[str, ...]: ...

    @property
    def title(self) -> str: ...

    @property
    def group(self) -> str: ...


def key_word(name: str) -> str:
    """The cap of one key (a GTK key name, no modifiers): ``Page_Up`` → "Page Up", ``w`` → "W"."""
    if name in KEY_WORDS:
        return _(KEY_WORDS[name])
    if name in KEY_SIGNS:
        return KEY_SIGNS[name]
    if name.startswith("KP_"):
        rest = name[3:]
        return _(KEYPAD).format(key=KEYPAD_SIGNS.get(rest, rest))
    if len(name) == 1:
        return name.upper()
    return name.replace("_", " ")


def key_caps(accel: str) -> tuple[str, ...]:
    """The caps pressed together for one GTK accelerator: ``<Control>plus`` → ("Ctrl", "+")."""
    mods = _ACCEL.findall(accel)
    key = _ACCEL.sub("", accel)
    if not key:
        raise ValueError(f"no key in the accelerator {accel!r}")
    caps: list[str] = []
    for mod in mods:
        word = MODIFIERS.get(mod.lower())
        if word is None:
            raise ValueError(f"unknown modifier <{mod}> in {accel!r}")
        caps.append(_(word))
    caps.append(key_word(key))
    return tuple(caps)


def _run(accels: Sequence[str]) -> bool:
    """The keys differ only by a last digit counting up by one (``<Alt>1`` … ``<Alt>9``)."""
    if len(accels) < 3 or not all(a[-1:].isdigit() for a in accels):
        return False
    stems = {a[:-1] for a in accels}
    digits = [int(a[-1]) for a in accels]
    return len(stems) == 1 and digits == list(range(digits[0], digits[0] + len(digits)))


@dataclass(frozen=True, slots=True)
class KeyRow:
    """One line of the keys window: what the keys do, and the keys."""

    group: str
    """Its heading, translated."""
    title: str
    """What the keys do, translated."""
    accels: tuple[str, ...]
    """Every key of the table this row stands for (GTK accelerators)."""
    chords: tuple[tuple[str, ...], ...]
    """What is drawn: each chord's caps (``("Ctrl", "+")``) — the first and last of a run, or each key."""
    through: bool = False
    """``chords`` are the first and last of a run (drawn with "…" between them)."""

    def keys_words(self) -> str:
        """The keys in words, as a screen reader says them: "Ctrl+Q", "Alt+1 … Alt+9", "↑ / W"."""
        joined = ["+".join(chord) for chord in self.chords]
        return (" … " if self.through else " / ").join(joined)

    def spoken(self) -> str:
        """The row's accessible name: its words, then its keys."""
        return _("{title}: {keys}").format(title=self.title, keys=self.keys_words())


def folded(text: str) -> str:
    """``text`` folded for searching: no case, no accents (a search for "zoom" finds "Zóóm")."""
    decomposed = unicodedata.normalize("NFKD", text.casefold())
    return "".join(c for c in decomposed if not unicodedata.combining(c))


@dataclass(frozen=True, slots=True)
class KeySheet:
    """Every row of the table, in group order; :meth:`matching` is what a search leaves."""

    rows: tuple[KeyRow, ...]

    @classmethod
    def of(cls, table: Iterable[KeyEntry]) -> KeySheet:
        """The sheet of ``table`` (``keys.bindings()``): bindings with one heading and one title merged."""
        merged: dict[tuple[str, str], list[str]] = {}
        for b in table:
            keys = merged.setdefault((b.group, b.title), [])
            keys += [a for a in b.accels if a not in keys]
        rank = {name: i for i, name in enumerate(GROUP_ORDER)}
        order = sorted(merged, key=lambda gt: rank.get(gt[0], len(rank)))  # stable: the table's order within
        rows = []
        for group, title in order:
            accels = merged[(group, title)]
            through = _run(accels)
            shown = (accels[0], accels[-1]) if through else tuple(accels)
            rows.append(KeyRow(_(group), _(title), tuple(accels), tuple(key_caps(a) for a in shown), through))
        return cls(tuple(r for r in rows if r.accels))

    @property
    def groups(self) -> tuple[str, ...]:
        """The headings, in order, each once."""
        return tuple(dict.fromkeys(r.group for r in self.rows))

    def accels(self) -> set[str]:
        """Every key the sheet lists."""
        return {a for r in self.rows for a in r.accels}

    def matching(self, query: str) -> tuple[KeyRow, ...]:
        """The rows whose words, heading or keys hold every word of ``query`` (all rows for none)."""
        words = folded(query).split()
        if not words:
            return self.rows
        found = []
        for row in self.rows:
            haystack = folded(f"{row.group} {row.title} {' '.join(' '.join(c) for c in row.chords)}")
            if all(w in haystack for w in words):
                found.append(row)
        return tuple(found)


def count_note(shown: int, total: int, query: str) -> str:
    """What the window says under the search: nothing while every row shows, else how many match."""
    if not query.strip() or shown == total:
        return ""
    if not shown:
        return _("No key matches “{query}”").format(query=query.strip())
    return ngettext("{shown} of {total} key", "{shown} of {total} keys", total).format(
        shown=shown, total=total
    )
