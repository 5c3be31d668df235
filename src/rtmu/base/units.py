"""Numbers with their units as the operator's language writes them: ``1.234,5 m`` in German.

The one place the window and the CLI's human text turn a quantity into words. The number goes through
:func:`rtmu.base.i18n.number` (the language's decimal and grouping marks), the unit through the catalogue
(``{value} m``: where the unit goes and its spacing are the language's). ``--json``, files and anything sent
to a server keep plain numbers and never come here.
"""

from __future__ import annotations

from dataclasses import dataclass

from .i18n import N_, _, number

UNITS: dict[str, str] = {
    "m": N_("{value} m"),
    "mm": N_("{value} mm"),
    "m/s": N_("{value} m/s"),
    "mm/s": N_("{value} mm/s"),
    "deg": N_("{value}°"),
    "deg/s": N_("{value}°/s"),
    "%": N_("{value} %"),
    "V": N_("{value} V"),
    "s": N_("{value} s"),
    "ms": N_("{value} ms"),
    "min": N_("{value} min"),
    "h": N_("{value} h"),
    "B": N_("{value} B"),
    "kB": N_("{value} kB"),
    "MB": N_("{value} MB"),
    "GB": N_("{value} GB"),
    "fps": N_("{value} fps"),
    "kB/s": N_("{value} kB/s"),
}
"""Unit key → how the language writes a value with it (marked; translated where shown)."""


def quantity(value: float, unit: str, digits: int = 0) -> str:
    """``value`` (already in ``unit``) with ``digits`` decimals and its unit: ``quantity(1234.5, "m", 1)``
    → ``1,234.5 m`` in English, ``1.234,5 m`` in German; unit ``""``: the number alone."""
    shown = number(value, digits)
    return _(UNITS[unit]).format(value=shown) if unit else shown


def metres(mm: float, digits: int = 1) -> str:
    """A distance the protocol gives in millimetres, in metres: ``metres(1500)`` → ``1.5 m``."""
    return quantity(mm / 1000, "m", digits)


def percent(value: float) -> str:
    """A percentage (0–100): whole below 100 and above 10, one decimal below 10 (``2.4 %``)."""
    return quantity(value, "%", 1 if 0 < abs(value) < 10 else 0)


def file_size(size: int) -> str:
    """``1234567`` → ``1.2 MB`` (decimal units, as file managers show them)."""
    if size < 1000:
        return quantity(size, "B")
    value = float(size)
    for unit in ("kB", "MB", "GB"):
        value /= 1000.0
        if value < 999.5 or unit == "GB":
            return quantity(value, unit, 1 if value < 100 else 0)
    raise AssertionError("unreachable")


def duration(seconds: float) -> str:
    """A span for people: ``12.5 s`` below a minute, ``4 min`` below an hour, then ``1.5 h``."""
    if seconds < 60:
        return quantity(seconds, "s", 1 if seconds < 10 else 0)
    if seconds < 3600:
        return quantity(seconds / 60, "min")
    return quantity(seconds / 3600, "h", 1)


def coordinates(x_mm: float, y_mm: float, digits: int = 2) -> str:
    """A map position given in millimetres, in metres: ``1.50, -2.00 m`` (``1,50; -2,00 m`` where the
    decimal mark is the comma, so the two numbers stay apart)."""
    sep = "; " if number(0.5, 1)[1] == "," else ", "
    return _(UNITS["m"]).format(value=f"{number(x_mm / 1000, digits)}{sep}{number(y_mm / 1000, digits)}")


@dataclass(frozen=True, slots=True)
class Quantity:
    """A number with its unit inside a :class:`rtmu.base.i18n.Said`: plain English where the sentence is
    read by machines (``12.5 mm``), :func:`quantity` where it is shown to people (``12,5 mm``)."""

    value: float
    unit: str
    digits: int | None = 0
    """Decimals; None: as many as the value has (like ``:g``: ``5 s``, ``2.5 s``)."""

    def _digits(self) -> int:
        if self.digits is not None:
            return max(0, self.digits)
        text = f"{self.value:g}"
        return len(text.split(".")[1]) if "." in text and "e" not in text else 0

    def __str__(self) -> str:
        plain = f"{self.value:.{self._digits()}f}"
        return UNITS[self.unit].format(value=plain) if self.unit else plain

    def __format__(self, spec: str) -> str:
        return format(str(self), spec)

    def words(self) -> str:
        return quantity(self.value, self.unit, self._digits())
