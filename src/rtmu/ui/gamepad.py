"""libmanette → :class:`rtmu.control.gamepad.Gamepad`: the thin adapter, no decisions of its own.

libmanette (Debian's ``gir1.2-manette-0.2``) finds pads through udev and reads
them with evdev on the GTK main loop, so its signals arrive on the UI thread —
the thread the controller lives on. This module only translates its devices and
events into the mapping's calls; every rule (dead-man, silence, focus, rate
limit) is in ``rtmu.control.gamepad``. Without libmanette (another distribution, no
typelib) the window simply has no gamepad.
"""

from __future__ import annotations

import logging
from typing import Any

from ..control.gamepad import AXIS_CODES, BUTTON_CODES, Gamepad

log = logging.getLogger(__name__)

_SIGNALS = (
    ("button-press-event", "_on_press"),
    ("button-release-event", "_on_release"),
    ("absolute-axis-event", "_on_axis"),
    ("hat-axis-event", "_on_hat"),
    ("disconnected", "_on_device_gone"),
)


def load_manette() -> Any | None:
    """The ``Manette`` module, or None when libmanette's typelib is not installed."""
    try:
        import gi

        gi.require_version("Manette", "0.2")
        from gi.repository import Manette
    except (ImportError, ValueError) as exc:
        log.info("no gamepad support: %s", exc)
        return None
    return Manette


class ManettePads:
    """Watches libmanette's monitor and feeds the one pad ``pad`` listens to."""

    def __init__(self, pad: Gamepad) -> None:
        self.pad = pad
        self._handlers: dict[int, tuple[Any, list[int]]] = {}
        self._monitor: Any | None = None
        self._monitor_handlers: list[int] = []
        manette = load_manette()
        self.available = manette is not None
        if manette is None:
            return
        try:
            monitor = manette.Monitor.new()
        except Exception as exc:  # udev missing in a container: no pads, nothing else breaks
            log.warning("gamepads unavailable: %s", exc)
            self.available = False
            return
        self._monitor = monitor
        self._monitor_handlers = [
            monitor.connect("device-connected", lambda _m, d: self._add(d)),
            monitor.connect("device-disconnected", lambda _m, d: self._on_device_gone(d)),
        ]
        devices = monitor.iterate()
        while True:
            found, device = devices.next()
            if not found:
                break
            if device is not None:
                self._add(device)

    def _add(self, device: Any) -> None:
        name = str(device.get_name() or "Gamepad")[:80]
        if not self.pad.connected(device, name):
            return
        ids = [device.connect(sig, getattr(self, method)) for sig, method in _SIGNALS]
        self._handlers[id(device)] = (device, ids)

    def _on_press(self, device: Any, event: Any) -> None:
        found, code = event.get_button()
        if found and code in BUTTON_CODES:
            self.pad.button(device, BUTTON_CODES[code], True)
        elif found:
            self.pad.button(device, f"code_{code}", True)  # still a sign of life

    def _on_release(self, device: Any, event: Any) -> None:
        found, code = event.get_button()
        if found:
            self.pad.button(device, BUTTON_CODES.get(code, f"code_{code}"), False)

    def _on_axis(self, device: Any, event: Any) -> None:
        found, axis, value = event.get_absolute()
        if found:
            self.pad.axis(device, AXIS_CODES.get(axis, f"axis_{axis}"), float(value))

    def _on_hat(self, device: Any, event: Any) -> None:
        found, axis, value = event.get_hat()
        if found:
            self.pad.hat(device, int(axis), int(value))

    def _on_device_gone(self, device: Any) -> None:
        self.pad.disconnected(device)
        entry = self._handlers.pop(id(device), None)
        if entry is not None:
            for handler in entry[1]:
                if device.handler_is_connected(handler):
                    device.disconnect(handler)

    def close(self) -> None:
        """Stop listening (the window is closing); a pad that drove is released first."""
        for device, _ids in list(self._handlers.values()):
            self._on_device_gone(device)
        if self._monitor is not None:
            for handler in self._monitor_handlers:
                self._monitor.disconnect(handler)
            self._monitor = None
