"""Connection profiles and view choices, kept in the user's config directory (skeleton; see below)."""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_PORT = 7272


@dataclass(frozen=True, slots=True)
class Profile:
    """One robot server the operator connects to, and how they left the view last time."""

    name: str = "default"
    host: str = "127.0.0.1"
    port: int = DEFAULT_PORT
    user: str = ""
    remember_password: bool = False
    """Keep the password in the desktop keyring (never in the settings file)."""
    auto_reconnect: bool = True
    zoom: float = 0.0
    follow_robot: bool = True
    show_sonar: bool = True
    speed: int = 50
