"""``rtmu --version``: what this RTMU is and what it runs on, for a bug report or a support call.

It says RTMU's version, the ArNetworking dialect it speaks, and the versions of Python, PyGObject,
GLib, GTK and libadwaita. The toolkit versions come from the shared libraries themselves (ctypes) and
PyGObject's from its package metadata, so the answer costs no GTK import and needs no display. The
metadata is read straight from the ``.dist-info`` on the path (``importlib.metadata`` alone would
cost ``rtmu --version`` a fifth of its start-up), and ctypes is loaded only when the versions are
asked for: the ``rtmu`` command imports this module for every subcommand.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from . import __version__
from .protocol.commands import VERSION_TAG

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
    import ctypes

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
    """The version in the metadata of the first installed distribution ``name`` on ``sys.path`` (as
    ``importlib.metadata.version`` finds it: a ``.dist-info`` or ``.egg-info``, names compared
    case-insensitively with ``-``/``_``/``.`` alike), or "not installed"."""
    wanted = _normalized(name)
    for entry in sys.path:
        try:
            names = os.listdir(entry or ".")
        except OSError:
            continue
        for found in sorted(names):
            stem, dot, suffix = found.rpartition(".")
            if (
                not dot
                or suffix not in ("dist-info", "egg-info")
                or _normalized(stem.split("-")[0]) != wanted
            ):
                continue
            path = os.path.join(entry or ".", found)
            metadata = os.path.join(path, "METADATA" if suffix == "dist-info" else "PKG-INFO")
            if not os.path.isdir(path):
                metadata = path  # an egg-info file is the metadata itself
            version = _metadata_version(metadata)
            if version is not None:
                return version
    return "not installed"


def _normalized(name: str) -> str:
    return name.lower().replace("-", "_").replace(".", "_")


def _metadata_version(path: str) -> str | None:
    """The ``Version:`` header of a metadata file (the headers end at the first empty line)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                if not line.strip():
                    break
                if line.startswith("Version:"):
                    return line.partition(":")[2].strip()
    except OSError:
        return None
    return None


def version_lines() -> list[str]:
    """The report, one fact a line; the first line is the plain ``rtmu X.Y.Z``."""
    import platform

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
