"""The operator's commands: one small class each, in one registry — the only definition of a command.

A command says what it is called (``name``, ``label``), which keys run it and
under which heading the keys window lists them (``keys``, ``group``),
whether the robot menu offers it (``menu``), which server data it needs and when
it is enabled, and what it does to its :class:`CommandTarget` (the controller).
The window builds its actions (``win.<name>``, underscores as hyphens), its key
table, the robot menu and the keys window from :data:`COMMANDS`, and greys
a command out with the reason :meth:`Command.unavailable` gives (e.g. "this
server does not offer turnByAngle"). Adding a command = adding one class.

Keys use GTK accelerator syntax (``"Up"``, ``"plus"``, ``"<Control>d"``) but
nothing here imports GTK, nor the controller: a command knows its target only
through the :class:`CommandTarget` protocol.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Protocol

from ..base.i18n import N_
from ..values import intents
from ..values.intents import Intent
from ..values.state import Phase

LINKING = (Phase.CONNECTING, Phase.RECONNECTING, Phase.CONNECTED)
"""Phases in which there is something to disconnect (an attempt in progress can be cancelled)."""


class CommandContext(Protocol):
    """What a command may look at to decide whether it is enabled (the controller provides it)."""

    @property
    def connected(self) -> bool: ...

    def supports(self, name: str) -> bool: ...

    def image_source(self) -> str | None: ...

    def connection_phase(self) -> Phase: ...


class CommandTarget(Protocol):
    """What commands act on (``rtmu.control.controller.Controller`` provides it)."""

    def press(self, direction: str) -> None: ...

    def release(self, direction: str) -> None: ...

    def stop(self) -> None: ...

    def speed_up(self) -> None: ...

    def speed_down(self) -> None: ...

    def ask(self, intent: Intent) -> object:
        """Send an operator intent through the controller's guard."""

    def connect(self, password: str | None = None) -> None: ...

    def disconnect(self) -> None: ...

    def open_dialog(self, name: str) -> None:
        """Ask the window for the dialog ``name`` (``turn``, ``go``) that asks the operator for an amount."""


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
    keys: ClassVar[tuple[str, ...]] = ()
    """GTK accelerator strings that run it (the window's key table is built from these)."""
    group: ClassVar[str] = "Robot"
    """Heading in the keys window."""
    menu: ClassVar[bool] = False
    """Offered in the window's robot menu (greyed with its reason when unavailable)."""
    needs: ClassVar[tuple[str | tuple[str, ...], ...]] = ()
    """Server data names it needs; a tuple inside means "any one of these"."""
    needs_connection: ClassVar[bool] = True
    hold: ClassVar[bool] = False
    """True: active while the key is held (:meth:`activate` on press, :meth:`deactivate` on release)."""

    def unavailable(self, ctx: CommandContext) -> str | None:
        """None when the command can run now, else a sentence saying why not."""
        if self.needs_connection and not ctx.connected:
            return N_("not connected")
        for need in self.needs:
            options = need if isinstance(need, tuple) else (need,)
            if not any(ctx.supports(n) for n in options):
                return f"this server does not offer {' or '.join(options)}"
        return None

    def state(self, ctx: CommandContext) -> CommandState:
        reason = self.unavailable(ctx)
        return CommandState(reason is None, reason or "")

    def activate(self, target: CommandTarget) -> None:
        raise NotImplementedError

    def deactivate(self, target: CommandTarget) -> None:
        """Key released (hold commands only)."""


class CommandRegistry:
    """Commands by name, in registration order (menus keep that order)."""

    def __init__(self) -> None:
        self._commands: dict[str, Command] = {}

    def register(self, cls: type[Command]) -> type[Command]:
        if cls.name in self._commands:
            raise ValueError(f"two commands named {cls.name!r}")
        taken = self.keys()
        for key in cls.keys:
            if key in taken:
                raise ValueError(f"{cls.name}: key {key!r} already runs {taken[key]!r}")
        self._commands[cls.name] = cls()
        return cls

    def unregister(self, name: str) -> None:
        """Remove a command (tests add their own and take them away again)."""
        self._commands.pop(name, None)

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

    def keys(self) -> dict[str, str]:
        """accelerator → command name, for the view's key table."""
        return {key: c.name for c in self for key in c.keys}


def action_name(command_name: str) -> str:
    """The ``win.`` action of a command: GIO action names allow no underscores."""
    return command_name.replace("_", "-")


COMMANDS = CommandRegistry()
command = COMMANDS.register
"""Class decorator adding a command to the default registry."""


# -- held motion --------------------------------------------------------------------------------


class _HeldDrive(Command):
    direction: ClassVar[str]
    needs = ("ratioDrive",)
    hold = True

    def activate(self, target: CommandTarget) -> None:
        target.press(self.direction)

    def deactivate(self, target: CommandTarget) -> None:
        target.release(self.direction)


@command
class DriveForward(_HeldDrive):
    name = "drive_forward"
    label = N_("Drive forward (hold)")
    keys = ("Up", "w")
    group = "Driving"
    direction = "forward"


@command
class DriveBackward(_HeldDrive):
    name = "drive_backward"
    label = N_("Drive backward (hold)")
    keys = ("Down", "s")
    group = "Driving"
    direction = "backward"


@command
class DriveLeft(_HeldDrive):
    name = "drive_left"
    label = N_("Turn left (hold)")
    keys = ("Left", "a")
    group = "Driving"
    direction = "left"


@command
class DriveRight(_HeldDrive):
    name = "drive_right"
    label = N_("Turn right (hold)")
    keys = ("Right", "d")
    group = "Driving"
    direction = "right"


@command
class Stop(Command):
    name = "stop"
    label = N_("Stop")
    keys = ("space", "KP_5", "<Control>space")
    """Ctrl+Space stops too, in a text field as well (``key_rules``); listed so the keys window says so."""
    group = "STOP"
    needs = (("stop", "ratioDrive"),)

    def unavailable(self, ctx: CommandContext) -> str | None:
        # Stop is never greyed out while connected: it is always worth sending.
        return None if ctx.connected else "not connected"

    def activate(self, target: CommandTarget) -> None:
        target.stop()


# -- speed --------------------------------------------------------------------------------------


@command
class SpeedUp(Command):
    name = "speed_up"
    label = N_("Faster (+10 %)")
    keys = ("plus", "KP_Add", "equal")
    group = "Speed"
    needs_connection = False

    def activate(self, target: CommandTarget) -> None:
        target.speed_up()


@command
class SpeedDown(Command):
    name = "speed_down"
    label = N_("Slower (−10 %)")
    keys = ("minus", "KP_Subtract")
    group = "Speed"
    needs_connection = False

    def activate(self, target: CommandTarget) -> None:
        target.speed_down()


# -- bounded moves (what the thesis's operators asked for) ---------------------------------------


class _TurnBy(Command):
    degrees: ClassVar[float]
    needs = ("turnByAngle",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.TurnBy(self.degrees))


@command
class TurnDialog(Command):
    name = "turn"
    label = N_("Turn by an angle…")
    keys = ("t",)
    group = "Moves"
    menu = True
    needs = ("turnByAngle",)

    def activate(self, target: CommandTarget) -> None:
        target.open_dialog("turn")


@command
class GoDialog(Command):
    name = "go"
    label = N_("Go a distance…")
    keys = ("g",)
    group = "Moves"
    menu = True
    needs = ("moveDist",)

    def activate(self, target: CommandTarget) -> None:
        target.open_dialog("go")


@command
class TurnLeft90(_TurnBy):
    name = "turn_left_90"
    label = N_("Turn 90° left")
    keys = ("<Shift>Left",)
    group = "Moves"
    degrees = 90.0


@command
class TurnRight90(_TurnBy):
    name = "turn_right_90"
    label = N_("Turn 90° right")
    keys = ("<Shift>Right",)
    group = "Moves"
    degrees = -90.0


@command
class TurnAround(_TurnBy):
    name = "turn_around"
    label = N_("Turn around")
    keys = ("<Shift>Down",)
    group = "Moves"
    degrees = 180.0


@command
class MoveForward1m(Command):
    name = "move_forward_1m"
    label = N_("Go 1 m forward")
    keys = ("<Shift>Up",)
    group = "Moves"
    needs = ("moveDist",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.MoveDistance(1000.0))


# -- sensing ------------------------------------------------------------------------------------


@command
class RequestImage(Command):
    name = "request_image"
    label = N_("Camera picture")
    keys = ("i",)
    group = "Window"

    def unavailable(self, ctx: CommandContext) -> str | None:
        if not ctx.connected:
            return N_("not connected")
        if ctx.image_source() is None:
            return N_("this server offers no camera pictures (getPicture… or sendVideo)")
        return None

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.RequestPicture())


@command
class SafeDriveOn(Command):
    name = "safe_drive_on"
    label = N_("Safe drive on")
    needs = ("setSafeDrive",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.SetSafeDrive(True))


@command
class SafeDriveOff(Command):
    name = "safe_drive_off"
    label = N_("Safe drive off (no obstacle limits)")
    needs = ("setSafeDrive",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.SetSafeDrive(False))


# -- navigation (the server drives; a STOP or a drive key cancels it) ----------------------------


@command
class Home(Command):
    name = "home"
    label = N_("Go home")
    group = "Navigation"
    menu = True
    needs = ("home",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.GoHome())


@command
class DockCommand(Command):
    name = "dock"
    label = N_("Dock and charge")
    group = "Navigation"
    menu = True
    needs = ("dock",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.Dock())


@command
class TourGoals(Command):
    name = "tour_goals"
    label = N_("Tour the goals")
    group = "Navigation"
    menu = True
    needs = ("tourGoals",)

    def activate(self, target: CommandTarget) -> None:
        target.ask(intents.TourGoals())


# -- the server's own commands ------------------------------------------------------------------


@command
class ServerCommands(Command):
    """The palette of the server's own commands (listCommands, listStringCommands)."""

    name = "server_commands"
    label = N_("Server commands…")
    keys = ("<Control>k",)
    menu = True
    needs = (("listCommands", "listStringCommands", "customListCommands", "customListStringCommands"),)

    def activate(self, target: CommandTarget) -> None:
        target.open_dialog("commands")


# -- session ------------------------------------------------------------------------------------


@command
class Connect(Command):
    name = "connect"
    label = N_("Connect")
    keys = ("<Control>o",)
    group = "Connection"
    needs_connection = False

    def unavailable(self, ctx: CommandContext) -> str | None:
        return N_("already connected") if ctx.connected else None

    def activate(self, target: CommandTarget) -> None:
        target.connect()


@command
class Disconnect(Command):
    name = "disconnect"
    label = N_("Disconnect")
    keys = ("<Control>d",)
    group = "Connection"

    def unavailable(self, ctx: CommandContext) -> str | None:
        # Also while connecting or reconnecting: the button says "Disconnect" then and cancels.
        return None if ctx.connection_phase() in LINKING else "not connected"

    def activate(self, target: CommandTarget) -> None:
        target.disconnect()
