"""The operator's language: RTMU's gettext domain ``rtmu``, read from the catalogues in the package.

The compiled catalogues live in ``rtmu/data/locale/<lang>/LC_MESSAGES/rtmu.mo`` (``package_data``), so an
installed wheel and a checkout read the same files. The language comes from the environment as gettext
reads it (``LANGUAGE``, then ``LC_ALL``, ``LC_MESSAGES``, ``LANG``); a language without a catalogue, or
``C``, shows RTMU's own English. ``scripts/i18n.py`` (``./rtmu-dev i18n``) extracts, merges and compiles.

Words a module keeps as constants are marked with :func:`N_` and translated where they are shown, so the
language chosen when the window opens — not when the module was imported — is the one the operator reads.
Text a robot's server sends (popups, status, configuration, map and command names) is never passed here:
it is the robot's own words and is shown as sent.
"""

from __future__ import annotations

import contextlib
import gettext
import locale
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

from rtmu.package_data import LOCALE_DIR

DOMAIN = "rtmu"

LOCALE_DIR_VARIABLE = "RTMU_LOCALE_DIR"
"""Where to read the catalogues instead of the package (set by :func:`child_environment` for the
processes RTMU starts when this one reads other catalogues: the tests' pseudo-locale)."""

_active: list[gettext.NullTranslations] = []
_chosen: list[tuple[tuple[str, ...], Path | None]] = []


def use(languages: Sequence[str] | None = None, localedir: Path | None = None) -> gettext.NullTranslations:
    """Choose the catalogue every later ``_()`` reads: ``languages`` in order of preference (``None``:
    the environment's), from ``localedir`` (``$RTMU_LOCALE_DIR``, else the package's; tests give the
    pseudo-locale's)."""
    folder = localedir or Path(os.environ.get(LOCALE_DIR_VARIABLE) or LOCALE_DIR)
    translation = gettext.translation(
        DOMAIN, str(folder), languages=list(languages) if languages else None, fallback=True
    )
    _active[:] = [translation]
    _chosen[:] = [(tuple(languages), localedir)] if languages else []
    return translation


def child_environment() -> dict[str, str]:
    """What a process RTMU starts (the guardian) needs in its environment to speak the language this
    one speaks: ``LANGUAGE`` (and where the catalogues are) when the language was chosen here rather
    than by the environment — a child inherits the environment, not a choice made in this process."""
    if not _chosen:
        return {}
    languages, localedir = _chosen[0]
    env = {"LANGUAGE": ":".join(languages)}
    if localedir is not None:
        env[LOCALE_DIR_VARIABLE] = str(localedir)
    return env


def _translation() -> gettext.NullTranslations:
    if not _active:
        use()
    return _active[0]


def _(message: str) -> str:
    """``message`` in the operator's language."""
    return _translation().gettext(message)


def ngettext(singular: str, plural: str, n: int) -> str:
    """The form of ``singular``/``plural`` the operator's language uses for ``n`` (its own plural rule)."""
    return _translation().ngettext(singular, plural, n)


def N_(message: str) -> str:
    """Mark ``message`` for extraction only: it is translated with ``_()`` where it is shown."""
    return message


class Said(str):
    """A sentence built from values that both machines and people read: as a ``str`` it is the English
    (``--json``, logs, comparisons — stable whatever the operator's language); :meth:`words` says it in
    the operator's language, numbers and all, when it is shown.

    ``Said(N_("connected to {where} in {time}"), where=..., time=Quantity(12, "ms"))``: the template is
    marked where it is written and translated at display time; a value with a ``words()`` method (a
    :class:`Said`, a :class:`rtmu.base.units.Quantity`) is said in the operator's language too, any
    other value is shown as it is (a host, the server's own words)."""

    template: str
    values: dict[str, object]

    def __new__(cls, template: str, /, **values: object) -> Said:
        said = super().__new__(cls, template.format(**values))
        said.template = template
        said.values = values
        return said

    def words(self) -> str:
        """The sentence in the operator's language."""
        shown = {k: _value_words(v) for k, v in self.values.items()}
        try:
            return _(self.template).format(**shown)
        except (KeyError, IndexError, ValueError):  # a translation that broke its placeholders
            return self.template.format(**shown)

    def __reduce__(self) -> tuple[object, ...]:
        return (_said, (self.template, self.values))


def _value_words(value: object) -> object:
    say = getattr(value, "words", None)
    return say() if callable(say) else value


def _said(template: str, values: dict[str, object]) -> Said:
    return Said(template, **values)


def as_said(text: str) -> Said:
    """``text`` as a :class:`Said` (itself if it is one): a marked constant becomes one with no values,
    so a sentence joined from parts still says each part in the operator's language."""
    return text if isinstance(text, Said) else Said(text.replace("{", "{{").replace("}", "}}"))


def error_words(error: BaseException) -> str:
    """An exception's message for the operator: its :class:`Said` in their language, else as raised."""
    said = error.args[0] if len(error.args) == 1 and isinstance(error.args[0], Said) else None
    return said.words() if said is not None else str(error)


def words(text: str) -> str:
    """``text`` as the operator reads it: a :class:`Said` in their language, a marked constant
    translated (an unmarked text — a host, the server's words — comes back as it is)."""
    if isinstance(text, Said):
        return text.words()
    return _(text) if text else text


# TRANSLATORS: 1234.5 as your language writes it, with its grouping mark (or none) and decimal mark.
NUMBER_PATTERN = N_("1,234.5")
"""Translators write one thousand two hundred thirty-four and a half as their language does (German:
``1.234,5``): its grouping mark (or none) and decimal mark are read from it, so numbers follow the
operator's language even where the C library lacks that locale."""

_PATTERN = re.compile(r"1([^\d]?)234([^\d])5")


def number(value: float, digits: int = 0) -> str:
    """``value`` with ``digits`` decimals as the operator's language writes numbers (its decimal mark and
    grouping), for numbers shown to people; machine output (JSON, files, the wire) never goes through here.

    The marks come from the chosen catalogue's :data:`NUMBER_PATTERN`; with no catalogue (English, ``C``)
    from the C library's ``LC_NUMERIC``."""
    digits = max(0, digits)
    marks = _catalogue_marks()
    if marks is None:
        marks = _locale_marks()
        if marks is None:  # a grouping other than every three digits: the C library's own way
            return locale.format_string(f"%.{digits}f", value, grouping=True)
    group, decimal = marks
    return f"{value:,.{digits}f}".translate({ord(","): group, ord("."): decimal})


def parse_number(text: str) -> float:
    """A number a person typed as their language writes numbers (German ``1.234,5``; English
    ``1,234.5`` or ``1234.5``): its grouping marks dropped, its decimal mark read as the point. A field
    that shows what :func:`number` wrote reads it back. ValueError when ``text`` is no finite number."""
    group, decimal = _marks()
    plain = text.strip().replace("\u2212", "-")  # the minus sign a typographer (or GTK) may use
    if "_" in plain:
        raise ValueError(f"not a number: {text!r}")
    for mark in {group, "\u00a0", "\u202f"} - {"", decimal}:  # the group mark, and spaces used as one
        plain = plain.replace(mark, "")
    value = float(plain.replace(decimal, ".") if decimal != "." else plain)
    if not math.isfinite(value):
        raise ValueError(f"not a number: {text!r}")
    return value


def _marks() -> tuple[str, str]:
    """(grouping mark, decimal mark) of the operator's language: the catalogue's, else the C library's."""
    marks = _catalogue_marks() or _locale_marks()
    if marks is not None:
        return marks
    _numeric_locale()  # a grouping other than by threes: its marks still read as they are written
    conventions = locale.localeconv()
    return str(conventions["thousands_sep"]), str(conventions["decimal_point"]) or "."


def _locale_marks() -> tuple[str, str] | None:
    """(grouping mark, decimal mark) of ``LC_NUMERIC``, read once: ``locale.format_string`` took 60 µs a
    number, and the toolbar and the map's words write hundreds a second while driving (issue 28). None
    when the locale groups other than by threes (then ``locale`` formats each number)."""
    if not _locale_read:
        _numeric_locale()
        conv = locale.localeconv()
        grouping = list(conv["grouping"])
        group = str(conv["thousands_sep"]) if grouping and grouping[0] > 0 else ""
        by_threes = not group or grouping in ([3, 0], [3, 3, 0], [3, locale.CHAR_MAX])
        _locale_read.append((group, str(conv["decimal_point"])) if by_threes else None)
    return _locale_read[0]


_locale_read: list[tuple[str, str] | None] = []


def _catalogue_marks() -> tuple[str, str] | None:
    """(grouping mark, decimal mark) of the chosen catalogue, or None when it does not say; read once
    per catalogue (the toolbar writes numbers many times a second)."""
    translation = _translation()
    if _marks_read and _marks_read[0][0] is translation:
        return _marks_read[0][1]
    written = translation.gettext(NUMBER_PATTERN)
    found = _PATTERN.search(written) if written != NUMBER_PATTERN else None
    marks = (found.group(1), found.group(2)) if found else None
    _marks_read[:] = [(translation, marks)]
    return marks


_marks_read: list[tuple[gettext.NullTranslations, tuple[str, str] | None]] = []


_numeric_set: list[bool] = []


def _numeric_locale() -> None:
    """Take LC_NUMERIC from the environment once (GTK does the same at start); a locale the system does
    not have leaves C's."""
    if _numeric_set:
        return
    _numeric_set.append(True)
    with contextlib.suppress(locale.Error):
        locale.setlocale(locale.LC_NUMERIC, "")
