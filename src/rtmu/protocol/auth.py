"""ARIA's password digest and user-info file (protocol §2.5–2.6).

The client proves its password with ``md5(serverKey + passwordKey + password)``
sent as 16 raw bytes; the server, when it loaded a user file, computes the same
and compares.
"""

from __future__ import annotations

import hashlib
import re
import secrets
from dataclasses import dataclass, field
from pathlib import Path

from .fields import encode_text

_ALNUM = re.compile(r"[A-Za-z0-9]+")
PASSWORD_KEY_ALPHABET = "".join(chr(c) for c in range(0x30, 0x7A))
"""Characters ARIA draws a connection's password key from: ``0`` through ``y``."""


def password_digest(password: str, password_key: str, server_key: str = "") -> bytes:
    return hashlib.md5(encode_text(server_key) + encode_text(password_key) + encode_text(password)).digest()


def make_password_key(rng: secrets.SystemRandom | None = None, length: int | None = None) -> str:
    """A fresh per-connection key like ARIA's: 0–99 characters from ``0``…``y``."""
    rng = rng or secrets.SystemRandom()
    n = rng.randint(16, 32) if length is None else length
    return "".join(rng.choice(PASSWORD_KEY_ALPHABET) for _ in range(n))


@dataclass(frozen=True)
class User:
    name: str
    password: str
    groups: frozenset[str] = field(default_factory=frozenset)

    def may_use(self, command_group: str) -> bool:
        if not command_group:
            return True
        lowered = {g.lower() for g in self.groups}
        return "all" in lowered or command_group.lower() in lowered


class UserFileError(ValueError):
    """The user-info file is not in ARIA's ``UserInfoVersion1`` format."""


@dataclass
class UserTable:
    """Users of a server, from ARIA's user-info file; names compare case-insensitively."""

    users: dict[str, User] = field(default_factory=dict)

    @classmethod
    def parse(cls, text: str, source: str = "<users>") -> UserTable | None:
        """Parse a user file; None if it says ``doNotUse`` (ARIA then ignores the file)."""
        table = cls()
        seen_version = False
        for number, line in enumerate(text.splitlines(), 1):
            words = line.split()
            if not words or words[0].startswith(("#", ";")):
                continue
            keyword = words[0].lower()
            if keyword == "userinfoversion1":
                seen_version = True
            elif keyword == "donotuse":
                return None
            elif keyword == "user":
                if len(words) < 3 or not _ALNUM.fullmatch(words[1]) or not _ALNUM.fullmatch(words[2]):
                    raise UserFileError(f"{source}:{number}: expected 'user NAME PASSWORD [GROUP ...]'")
                table.users[words[1].lower()] = User(words[1], words[2], frozenset(words[3:]))
            else:
                raise UserFileError(f"{source}:{number}: unknown keyword {words[0]!r}")
        if not seen_version:
            raise UserFileError(f"{source}: the first keyword must be UserInfoVersion1")
        return table

    @classmethod
    def load(cls, path: str | Path) -> UserTable | None:
        p = Path(path)
        return cls.parse(p.read_text(encoding="latin-1"), str(p))

    def check(self, name: str, digest: bytes, password_key: str, server_key: str = "") -> User | None:
        """The user if name and digest match, else None (ARIA's reason 1 covers every failure)."""
        if not _ALNUM.fullmatch(name):
            return None
        user = self.users.get(name.lower())
        if user is None:
            return None
        expected = password_digest(user.password, password_key, server_key)
        return user if secrets.compare_digest(expected, digest) else None
