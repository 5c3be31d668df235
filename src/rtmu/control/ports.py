"""What the controller talks to: the window (:class:`View`), the network side (:class:`ClientLink`) and
the remembered passwords (:class:`SecretStore`), as small protocols, so the controller stays GTK-free and
its rules are tested without a display or a socket; :class:`NoView` for a controller no window shows."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Protocol

from ..base.notices import Notice
from ..client.lease import DriveLease
from ..settings.store import Profile
from ..values.intents import Intent
from ..values.target import Target
from .commands import CommandState


class View(Protocol):
    """What the controller needs from a window (GTK, a test fake, or nothing at all)."""

    def notify(self, notice: Notice) -> None:
        """Show a short message (banner/toast) to the operator; its kind says where."""

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        """Enable/disable commands; ``states`` holds every command whose state changed."""

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        """Ask for the password of ``profile`` without blocking; call ``answer`` (None = cancelled)."""

    def open_dialog(self, name: str) -> None:
        """Open the dialog a command needs (``turn``: an angle, ``go``: a distance)."""

    def driving(self) -> None:
        """A held drive began (a lease was granted) or a jog is watched: from now while
        :attr:`~rtmu.control.controller.Controller.needs_tick`, call
        :meth:`~rtmu.control.controller.Controller.tick` every :data:`~rtmu.control.held_drive.TICK` s
        (a window runs that timer only while something is driven)."""


class ClientLink(Protocol):
    """The network side as the controller sees it (``rtmu.client.ClientRunner``); every call returns at once
    (what it returns — a Future in the runner — is not waited for here).

    Results come back through the model (connection, robot, map, camera) on the
    UI thread; problems the operator should hear about go to ``on_notice``.
    """

    lease: DriveLease
    on_notice: Callable[[Notice], None] | None
    """Set by the controller: the network side's messages for the operator."""

    def connect(self, target: Target) -> object: ...

    def disconnect(self) -> object: ...

    def send(self, intent: Intent) -> Any:
        """The one way an intent crosses to the network thread (a Future of the feed's answer)."""

    # Optional (the password lookup looks for it with getattr): ``run_blocking(fn, done)`` runs ``fn``
    # off the UI thread and posts ``done(result)`` back; keyring lookups go through it.


class SecretStore(Protocol):
    """Where remembered passwords live (``rtmu.settings.store`` provides the keyring-backed one)."""

    def get(self, profile: Profile) -> str | None: ...


class NoView:
    """The view of a controller no window shows (yet): notices and command states go nowhere."""

    def notify(self, notice: Notice) -> None:
        pass

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        pass

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        answer(None)

    def open_dialog(self, name: str) -> None:
        pass

    def driving(self) -> None:
        pass
