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
from collections.abc import Sequence
from pathlib import Path

from rtmu.package_data import LOCALE_DIR

DOMAIN = "rtmu"

_active: list[gettext.NullTranslations] = []


def use(languages: Sequence[str] | None = None, localedir: Path | None = None) -> gettext.NullTranslations:
    """Choose the catalogue every later ``_()`` reads: ``languages`` in order of preference (``None``:
    the environment's), from ``localedir`` (the package's by default; tests give the pseudo-locale's)."""
    translation = gettext.translation(
        DOMAIN, str(localedir or LOCALE_DIR), languages=list(languages) if languages else None, fallback=True
    )
    _active[:] = [translation]
    return translation


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


def number(value: float, digits: int = 0) -> str:
    """``value`` with ``digits`` decimals as the operator's locale writes numbers (its decimal mark and
    grouping), for numbers shown to people; machine output (JSON, files) never goes through here."""
    _numeric_locale()
    return locale.format_string(f"%.{max(0, digits)}f", value, grouping=True)


_numeric_set: list[bool] = []


def _numeric_locale() -> None:
    """Take LC_NUMERIC from the environment once (GTK does the same at start); a locale the system does
    not have leaves C's."""
    if _numeric_set:
        return
    _numeric_set.append(True)
    with contextlib.suppress(locale.Error):
        locale.setlocale(locale.LC_NUMERIC, "")
