"""Where a connect's password comes from when none was given: remembered, else asked.

A remembered password is looked up off the UI thread when the link offers ``run_blocking`` (a keyring
may block on D-Bus or an unlock prompt); the connection starts when the answer comes back, unless the
profile changed or a connection started meanwhile. A password the store does not have, or a profile
that does not remember one, is asked of the operator without blocking; cancelling says so.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..settings.store import Profile
from .ports import ClientLink, SecretStore, View


class PasswordHost(Protocol):
    """What the lookup reads of its controller at each step (the window may swap its view and secrets)."""

    profile: Profile
    secrets: SecretStore | None
    link: ClientLink
    view: View


class PasswordLookup:
    """The password step of one controller's connect; ``start(password)`` connects, ``busy()`` says a
    connection is already starting or up (then an answer that comes late starts nothing)."""

    def __init__(self, host: PasswordHost, start: Callable[[str], None], busy: Callable[[], bool]) -> None:
        self._host = host
        self._start = start
        self._busy = busy
        self.pending = False
        """A keyring lookup runs off the UI thread; a connect waits for its answer."""

    def find(self, profile: Profile) -> None:
        """Find ``profile``'s password (remembered, else asked), then start the connection with it."""
        secrets = self._host.secrets
        if profile.remember_password and secrets is not None:
            self._look_up(profile, secrets)
            return
        self._host.view.ask_password(profile, self._answered)

    def _look_up(self, profile: Profile, secrets: SecretStore) -> None:
        run_blocking = getattr(self._host.link, "run_blocking", None)
        if run_blocking is None:  # a link without a worker: look it up here
            self._found(profile, secrets.get(profile))
            return
        self.pending = True

        def found(password: str | None) -> None:
            self.pending = False
            self._found(profile, password)

        run_blocking(lambda: secrets.get(profile), found)

    def _found(self, profile: Profile, password: str | None) -> None:
        if profile != self._host.profile or self._busy():
            return  # another profile was chosen, or a connection started, while we looked
        if password is None:
            self._host.view.ask_password(profile, self._answered)
            return
        self._start(password)

    def _answered(self, password: str | None) -> None:
        if password is None:
            self._host.view.notify(Notice.info(Kind.CONNECTION, _("Connection cancelled")))
            return
        self._start(password)
