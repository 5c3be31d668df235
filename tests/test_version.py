"""``rtmu --version``: RTMU's version, its protocol, and the real toolkit versions, without loading GTK."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import gi

from rtmu.versions import library_version, package_version

ROOT = Path(__file__).resolve().parents[1]


def _run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_version_names_rtmu_the_protocol_and_the_toolkit_as_installed() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "rtmu", "--version"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert lines[0] == f"rtmu {version}"
    assert 'introduction tag "alpha"' in lines[1] and "6MTX" in lines[1]
    gi.require_version("Gtk", "4.0")
    gi.require_version("Adw", "1")
    from gi.repository import Adw, GLib, Gtk

    gtk = f"{Gtk.get_major_version()}.{Gtk.get_minor_version()}.{Gtk.get_micro_version()}"
    adw = f"{Adw.get_major_version()}.{Adw.get_minor_version()}.{Adw.get_micro_version()}"
    assert f"PyGObject {gi.__version__}" in lines[2]
    assert f"GTK {gtk}" in lines[2] and f"libadwaita {adw}" in lines[2]
    glib = lines[2].split("GLib ")[1].split(",")[0]
    major, minor, micro = (int(p) for p in glib.split("."))
    assert GLib.check_version(major, minor, micro) is None  # the running GLib is at least that …
    assert GLib.check_version(major, minor, micro + 1) is not None  # … and not newer


def test_version_imports_no_gtk() -> None:
    code = (
        "import sys\nfrom rtmu.cli import main\ntry:\n    main(['--version'])\nexcept SystemExit as e:\n"
        "    assert e.code in (0, None), e.code\n"
        "print(sorted(m for m in sys.modules if m.startswith('gi.repository')))"
    )
    assert _run(code).splitlines()[-1] == "[]"


def test_a_missing_library_or_package_is_said_not_raised() -> None:
    assert library_version("libno-such-rtmu-lib.so.9", ("x_major",), False) == "not found"
    assert library_version("libglib-2.0.so.0", ("no_such_symbol_rtmu",), True) == "not found"
    assert package_version("no-such-rtmu-package") == "not installed"
