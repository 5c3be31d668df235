"""The operator's commands: one small class each, in one registry.

A command says what it is called, what key runs it by default, which server
data it needs and when it is enabled; running it calls the controller. The view
builds its actions, menu entries and key bindings from :data:`COMMANDS`, and
greys out a command with the reason :meth:`Command.unavailable` gives (e.g.
"this server does not offer turnByAngle"). Adding a command = adding one class
to this file.

Keys use GTK accelerator syntax (``"Up"``, ``"plus"``, ``"<Control>d"``) but
nothing here imports GTK.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Protocol

from .state import Phase

if TYPE_CHECKING:
    from .controller import Controller

LINKING = (Phase.CONNECTING, Phase.RECONNECTING, Phase.CONNECTED)
"""Phases in which there is something to disconnect (an attempt in progress can be cancelled)."""


class CommandContext(Protocol):
    """What a command may look at to decide whether it is enabled (the controller provides it)."""

    @property
    def connected(self) -> bool: ...

    def supports(self, name: str) -> bool: ...

    def image_source(self) -> str | None: ...

    def connection_phase(self) -> Phase: ...


@dataclass(frozen=True, slots=True)
class CommandState:
    enabled: bool
    reason: str = ""
    """Why it is disabled ("" when enabled)."""


class Command:
    """Base class. Subclasses set the class attributes and override :meth:`activate`."""

    name: ClassVar[str]
    """Stable identifier (action name), lower_snake_case."""
    label: ClassVar[str]
    """Short text for menus and tooltips."""
    default_key: ClassVar[str | None] = None
    """GTK accelerator string, or None."""
    needs: ClassVar[tuple[str | tuple[str, ...], ...]] = ()
    """Server data names it needs; a tuple inside means "any one of these"."""
    needs_connection: ClassVar[bool] = True
    hold: ClassVar[bool] = False
    """True: active while the key is held (:meth:`activate` on press, :meth:`deactivate` on release)."""

    def unavailable(self, ctx: CommandContext) -> str | None:
        """None when the command can run now, else a sentence saying why not."""
        if self.needs_connection and not ctx.connected:
            return "not connected"
        for need in self.needs:
            options = need if isinstance(need, tuple) else (need,)
            if not any(ctx.supports(n) for n in options):
                return f"this server does not offer {' or '.join(options)}"
        return None

    def state(self, ctx: CommandContext) -> CommandState:
        reason = self.unavailable(ctx)
        return CommandState(reason is None, reason or "")

    def activate(self, controller: Controller) -> None:
        raise NotImplementedError

    def deactivate(self, controller: Controller) -> None:
        """Key released (hold commands only)."""


class CommandRegistry:
    """Commands by name, in registration order (menus keep that order)."""

    def __init__(self) -> None:
        self._commands: dict[str, Command] = {}

    def register(self, cls: type[Command]) -> type[Command]:
        if cls.name in self._commands:
            raise ValueError(f"two commands named {cls.name!r}")
        self._commands[cls.name] = cls()
        return cls

    def get(self, name: str) -> Command:
        try:
            return self._commands[name]
        except KeyError:
            raise KeyError(f"no command named {name!r}") from None

    def __contains__(self, name: object) -> bool:
        return name in self._commands

    def __iter__(self) -> Iterator[Command]:
        return iter(self._commands.values())

    def __len__(self) -> int:
        return len(self._commands)

    def states(self, ctx: CommandContext) -> dict[str, CommandState]:
        return {c.name: c.state(ctx) for c in self}

    def default_keys(self) -> dict[str, str]:
        """accelerator → command name, for the view's key bindings."""
        return {c.default_key: c.name for c in self if c.default_key}


COMMANDS = CommandRegistry()
command = COMMANDS.register
"""Class decorator adding a command to the default registry."""


# -- held motion --------------------------------------------------------------------------------


class _HeldDrive(Command):
    direction: ClassVar[str]
    needs = ("ratioDrive",)
    hold = True

    def activate(self, controller: Controller) -> None:
        controller.press(self.direction)

    def deactivate(self, controller: Controller) -> None:
        controller.release(self.direction)


@command
class DriveForward(_HeldDrive):
    name = "drive_forward"
    label = "Forward (hold)"
    default_key = "Up"
    direction = "forward"


@command
class DriveBackward(_HeldDrive):
    name = "drive_backward"
    label = "Backward (hold)"
    default_key = "Down"
    direction = "backward"


@command
class DriveLeft(_HeldDrive):
    name = "drive_left"
    label = "Turn left (hold)"
    default_key = "Left"
    direction = "left"


@command
class DriveRight(_HeldDrive):
    name = "drive_right"
    label = "Turn right (hold)"
    default_key = "Right"
    direction = "right"


@command
class Stop(Command):
    name = "stop"
    label = "Stop"
    default_key = "space"
    needs = (("stop", "ratioDrive"),)

    def unavailable(self, ctx: CommandContext) -> str | None:
        # Stop is never greyed out while connected: it is always worth sending.
        return None if ctx.connected else "not connected"

    def activate(self, controller: Controller) -> None:
        controller.stop()


# -- speed --------------------------------------------------------------------------------------


@command
class SpeedUp(Command):
    name = "speed_up"
    label = "Faster (+10 %)"
    default_key = "plus"
    needs_connection = False

    def activate(self, controller: Controller) -> None:
        controller.speed_up()


@command
class SpeedDown(Command):
    name = "speed_down"
    label = "Slower (−10 %)"
    default_key = "minus"
    needs_connection = False

    def activate(self, controller: Controller) -> None:
        controller.speed_down()


# -- bounded moves (what the thesis's operators asked for) ---------------------------------------


class _TurnBy(Command):
    degrees: ClassVar[float]
    needs = ("turnByAngle",)

    def activate(self, controller: Controller) -> None:
        controller.turn_by(self.degrees)


@command
class TurnLeft90(_TurnBy):
    name = "turn_left_90"
    label = "Turn 90° left"
    default_key = "<Shift>Left"
    degrees = 90.0


@command
class TurnRight90(_TurnBy):
    name = "turn_right_90"
    label = "Turn 90° right"
    default_key = "<Shift>Right"
    degrees = -90.0


@command
class TurnAround(_TurnBy):
    name = "turn_around"
    label = "Turn around (180°)"
    default_key = "<Shift>Down"
    degrees = 180.0


@command
class MoveForward1m(Command):
    name = "move_forward_1m"
    label = "Go 1 m forward"
    default_key = "<Shift>Up"
    needs = ("moveDist",)

    def activate(self, controller: Controller) -> None:
        controller.move_distance(1000.0)


# -- sensing ------------------------------------------------------------------------------------


@command
class RequestImage(Command):
    name = "request_image"
    label = "Camera picture"
    default_key = "i"

    def unavailable(self, ctx: CommandContext) -> str | None:
        if not ctx.connected:
            return "not connected"
        if ctx.image_source() is None:
            return "this server offers no camera pictures (getPicture… or sendVideo)"
        return None

    def activate(self, controller: Controller) -> None:
        controller.request_image()


@command
class SafeDriveOn(Command):
    name = "safe_drive_on"
    label = "Safe drive on"
    needs = ("setSafeDrive",)

    def activate(self, controller: Controller) -> None:
        controller.set_safe_drive(True)


@command
class SafeDriveOff(Command):
    name = "safe_drive_off"
    label = "Safe drive off (no obstacle limits)"
    needs = ("setSafeDrive",)

    def activate(self, controller: Controller) -> None:
        controller.set_safe_drive(False)


# -- session ------------------------------------------------------------------------------------


@command
class Connect(Command):
    name = "connect"
    label = "Connect"
    default_key = "<Control>o"
    needs_connection = False

    def unavailable(self, ctx: CommandContext) -> str | None:
        return "already connected" if ctx.connected else None

    def activate(self, controller: Controller) -> None:
        controller.connect()


@command
class Disconnect(Command):
    name = "disconnect"
    label = "Disconnect"
    default_key = "<Control>d"

    def unavailable(self, ctx: CommandContext) -> str | None:
        # Also while connecting or reconnecting: the button says "Disconnect" then and cancels.
        return None if ctx.connection_phase() in LINKING else "not connected"

    def activate(self, controller: Controller) -> None:
        controller.disconnect()


# -- map view -----------------------------------------------------------------------------------


@command
class ZoomIn(Command):
    name = "zoom_in"
    label = "Zoom in"
    default_key = "<Control>plus"
    needs_connection = False

    def activate(self, controller: Controller) -> None:
        controller.zoom_in()


@command
class ZoomOut(Command):
    name = "zoom_out"
    label = "Zoom out"
    default_key = "<Control>minus"
    needs_connection = False

    def activate(self, controller: Controller) -> None:
        controller.zoom_out()


@command
class ZoomFit(Command):
    name = "zoom_fit"
    label = "Fit map"
    default_key = "<Control>0"
    needs_connection = False

    def activate(self, controller: Controller) -> None:
        controller.set_zoom(0.0)
