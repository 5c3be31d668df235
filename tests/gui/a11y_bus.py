"""An accessibility bus of the test's own: a private session bus, at-spi2-core's launcher on it.

The GUI tests run with ``GTK_A11Y=none`` (``conftest``): a shared or vanished accessibility bus must
not decide whether a window test passes. The accessibility test starts its own here — a session bus,
``at-spi-bus-launcher`` on it (which starts the accessibility bus; that bus starts
``at-spi2-registryd`` when the first application registers) — and gives its window and its reader
the environment to use it. The launcher never sees ``DISPLAY``, so it leaves no ``AT_SPI_BUS``
property on the tests' shared X screen; its socket goes under a private ``XDG_RUNTIME_DIR``, not the
``~/.cache/at-spi`` every run on the machine would share.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import gi

gi.require_version("Gio", "2.0")
from gi.repository import Gio, GLib  # noqa: E402

LAUNCHER_PLACES = ("/usr/libexec/at-spi-bus-launcher", "/usr/lib/at-spi2-core/at-spi-bus-launcher")


def launcher() -> str | None:
    """at-spi2-core's bus launcher (Debian and Ubuntu keep it out of PATH), or None."""
    return next((p for p in LAUNCHER_PLACES if os.access(p, os.X_OK)), shutil.which("at-spi-bus-launcher"))


def missing() -> str | None:
    """Why the accessibility test cannot run here, or None."""
    if launcher() is None:
        return "at-spi2-core's at-spi-bus-launcher is needed (apt-get install at-spi2-core)"
    if shutil.which("dbus-daemon") is None:
        return "dbus-daemon is needed (apt-get install dbus)"
    try:
        import pyatspi  # type: ignore[import-not-found]  # noqa: F401
    except ImportError:
        return "pyatspi is needed (apt-get install python3-pyatspi; scripts/setup.sh links it into the venv)"
    return None


def _read_line(proc: subprocess.Popen[bytes], fd: int, what: str) -> str:
    data = b""
    os.set_blocking(fd, False)
    deadline = time.monotonic() + 30
    while not data.endswith(b"\n"):
        if time.monotonic() > deadline or proc.poll() is not None:
            raise AssertionError(f"{what} did not start")
        try:
            chunk = os.read(fd, 256)
        except BlockingIOError:
            time.sleep(0.02)
            continue
        if not chunk:
            raise AssertionError(f"{what} did not start")
        data += chunk
    return data.decode().strip()


def _a11y_address(session_bus: str) -> str:
    """The accessibility bus the launcher on ``session_bus`` runs, asked as GTK asks (``org.a11y.Bus``)."""
    flags = Gio.DBusConnectionFlags.AUTHENTICATION_CLIENT | Gio.DBusConnectionFlags.MESSAGE_BUS_CONNECTION
    conn = Gio.DBusConnection.new_for_address_sync(session_bus, flags, None, None)
    deadline = time.monotonic() + 30
    try:
        while True:
            try:
                reply = conn.call_sync(
                    "org.a11y.Bus", "/org/a11y/bus", "org.a11y.Bus", "GetAddress",
                    None, GLib.VariantType("(s)"), Gio.DBusCallFlags.NONE, 5000, None,
                )  # fmt: skip
                return str(reply.unpack()[0])
            except GLib.Error:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
    finally:
        conn.close_sync(None)


@contextmanager
def accessibility_bus(runtime: Path) -> Iterator[dict[str, str]]:
    """Start the buses; yield the environment a window and a reader need; end all of it after."""
    runtime.mkdir(mode=0o700, parents=True, exist_ok=True)
    base = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "GTK_A11Y", "NO_AT_BRIDGE")}
    base["XDG_RUNTIME_DIR"] = str(runtime)
    read_fd, write_fd = os.pipe()
    bus = subprocess.Popen(
        ["dbus-daemon", "--session", "--nofork", f"--print-address={write_fd}"],
        pass_fds=(write_fd,), env=base, start_new_session=True,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    os.close(write_fd)
    launch: subprocess.Popen[bytes] | None = None
    try:
        address = _read_line(bus, read_fd, "the private session bus")
        base["DBUS_SESSION_BUS_ADDRESS"] = address
        launch = subprocess.Popen(
            [launcher() or "at-spi-bus-launcher", "--launch-immediately"],
            env=base, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        a11y = _a11y_address(address)
        env = {k: v for k, v in os.environ.items() if k not in ("GTK_A11Y", "NO_AT_BRIDGE")}
        env.update(DBUS_SESSION_BUS_ADDRESS=address, AT_SPI_BUS_ADDRESS=a11y, XDG_RUNTIME_DIR=str(runtime))
        yield env
    finally:
        os.close(read_fd)
        for proc in (launch, bus):  # the launcher's group holds its bus and the registry it started
            if proc is not None and proc.poll() is None:
                os.killpg(proc.pid, signal.SIGTERM)
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait(5)
