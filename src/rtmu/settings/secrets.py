"""Passwords in the desktop keyring: never in the settings file, never on a plain-text backend.

Split from :mod:`.store` (the settings file): the keyring is another store with its own rules — a
backend must be secure (Secret Service, KWallet…) or nothing is stored and the operator is asked at
connect time.
"""

from __future__ import annotations

import contextlib
import logging
import threading
from typing import Any, Protocol

log = logging.getLogger(__name__)

KEYRING_SERVICE = "rtmu"


class KeyedProfile(Protocol):
    """What the keyring needs of a profile (:class:`rtmu.settings.store.Profile`)."""

    @property
    def user(self) -> str: ...

    @property
    def keyring_user(self) -> str: ...


# -- passwords ---------------------------------------------------------------------------------


class KeyringSecrets:
    """Passwords in the desktop keyring via the ``keyring`` package.

    ``available`` is False when the package is missing or has no secure backend
    (no Secret Service on this desktop, or only a plain-text one): then nothing
    is stored and the operator is asked for the password at connect time.
    Calls may block (D-Bus): make them off the UI thread.
    """

    def __init__(self, backend: Any | None = None) -> None:
        self._given = backend
        self._loaded = backend is not None
        self._lock = threading.Lock()

    @property
    def _keyring(self) -> Any | None:
        """The backend, found the first time it is needed (finding it loads the keyring package and
        its plug-ins: 30 MiB and a tenth of a second that a window without a password never needs)."""
        with self._lock:
            if not self._loaded:
                self._given = _load_keyring()
                self._loaded = True
            return self._given

    @property
    def available(self) -> bool:
        return self._keyring is not None

    def get(self, profile: KeyedProfile) -> str | None:
        if not profile.user or self._keyring is None:
            return None
        try:
            return self._keyring.get_password(KEYRING_SERVICE, profile.keyring_user)
        except Exception as exc:  # a locked or broken keyring must not stop a connection
            log.warning("keyring lookup failed: %s", exc)
            return None

    def set(self, profile: KeyedProfile, password: str) -> bool:
        """Remember ``password``; False when no keyring is usable (the caller should then not promise it)."""
        if not profile.user or self._keyring is None:
            return False
        try:
            self._keyring.set_password(KEYRING_SERVICE, profile.keyring_user, password)
        except Exception as exc:
            log.warning("keyring store failed: %s", exc)
            return False
        return True

    def forget(self, profile: KeyedProfile) -> None:
        if not profile.user or self._keyring is None:
            return
        with contextlib.suppress(Exception):  # nothing stored is fine
            self._keyring.delete_password(KEYRING_SERVICE, profile.keyring_user)


_PLACEHOLDERS = ("keyring.backends.fail", "keyring.backends.null", "keyring.backends.chainer")
_INSECURE_WORDS = ("plaintext", "insecure", "unencrypted", "uncrypted", "file")


def is_secure_backend(backend: object) -> bool:
    """True for the keyring package's own encrypted stores (Secret Service, KWallet, Keychain…).

    Everything else is refused: ``keyrings.alt`` (``PlaintextKeyring`` writes passwords to a
    file in plain text; its "encrypted" file asks for a master password on the terminal),
    unknown third-party backends, and keyring's "no backend" placeholders.
    """
    cls = type(backend)
    module, name = cls.__module__, cls.__name__.lower()
    if not module.startswith("keyring.backends.") or module.startswith(_PLACEHOLDERS):
        return False
    return not any(word in name for word in _INSECURE_WORDS)


def choose_backend(backend: Any) -> Any | None:
    """The backend to use from what ``keyring.get_keyring()`` returned, or None if none is safe.

    A chain (several backends installed) is reduced to its best secure member, so a set
    can never fall through to a plain-text store.
    """
    if type(backend).__module__.startswith("keyring.backends.chainer"):
        members = getattr(backend, "backends", ())
        return next((b for b in members if is_secure_backend(b)), None)
    return backend if is_secure_backend(backend) else None


def _load_keyring() -> Any | None:
    try:
        import keyring
    except ImportError:
        return None
    try:
        backend = keyring.get_keyring()
    except Exception:
        return None
    chosen = choose_backend(backend)
    if chosen is None and not type(backend).__module__.startswith(
        ("keyring.backends.fail", "keyring.backends.null")
    ):
        log.warning(
            "not using the keyring backend %s: it does not keep passwords encrypted", type(backend).__name__
        )
    return chosen
