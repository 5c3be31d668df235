"""``rtmu --version``: what this RTMU is and what it runs on, for a bug report or a support call.

It says RTMU's version, the ArNetworking dialect it speaks, and the versions of Python, PyGObject,
GLib, GTK and libadwaita. The toolkit versions come from the shared libraries themselves (ctypes) and
PyGObject's from its package metadata, so the answer costs no GTK import and needs no display.
"""

from __future__ import annotations

import argparse
import ctypes
import importlib.metadata
import platform
from collections.abc import Sequence

from . import __version__
from .protocol.server_connection import VERSION_TAG

PROTOCOL = (
    f'ArNetworking as ARIA 2.9.1 speaks it (introduction tag "{VERSION_TAG}"); '
    "login protocol string: the server's own unless --protocol names one (Omron LD: 6MTX, older 5MTX)"
)
"""ArNetworking has no version number: servers enforce a free protocol string instead (docs/protocol.md)."""

_LIBRARIES = (
    ("GLib", "libglib-2.0.so.0", ("glib_major_version", "glib_minor_version", "glib_micro_version"), True),
    (
        "GTK",
        "libgtk-4.so.1",
        ("gtk_get_major_version", "gtk_get_minor_version", "gtk_get_micro_version"),
        False,
    ),
    (
        "libadwaita",
        "libadwaita-1.so.0",
        ("adw_get_major_version", "adw_get_minor_version", "adw_get_micro_version"),
        False,
    ),
)
"""(name, soname, its three version symbols, whether they are variables rather than functions)."""


def library_version(soname: str, symbols: Sequence[str], variables: bool) -> str:
    """A C library's own idea of its version, or why there is none (not installed, too old)."""
    try:
        lib = ctypes.CDLL(soname)
        if variables:
            parts = [ctypes.c_uint.in_dll(lib, name).value for name in symbols]
        else:
            parts = [int(getattr(lib, name)()) for name in symbols]
    except (OSError, AttributeError, ValueError):
        return "not found"
    return ".".join(str(p) for p in parts)


def package_version(name: str) -> str:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def version_lines() -> list[str]:
    """The report, one fact a line; the first line is the plain ``rtmu X.Y.Z``."""
    toolkit = ", ".join(
        f"{name} {library_version(so, symbols, var)}" for name, so, symbols, var in _LIBRARIES
    )
    return [
        f"rtmu {__version__}",
        f"protocol: {PROTOCOL}",
        f"Python {platform.python_version()}, PyGObject {package_version('PyGObject')}, {toolkit}",
    ]


class VersionAction(argparse.Action):
    """``--version``: print :func:`version_lines` and exit 0, like argparse's own version action."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS, help: str = "") -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help=help)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print("\n".join(version_lines()))
        parser.exit()
