"""Connection profiles and view choices in the user's config directory; passwords only in a keyring.

File: ``$XDG_CONFIG_HOME/rtmu/settings.toml`` (``~/.config/rtmu/settings.toml``
when the variable is unset), a small flat TOML document::

    version = 1
    last_profile = "lab"
    alarms_muted = true     # optional: the alarm beep is off (View > Alarm sound)
    near_people = true      # optional: View > Near people caps held driving …
    near_people_mm_s = 250  # … at this speed (mm/s, 50…1000; 250 when not given)
    # optional: [notifications] battery_low = false … switches a desktop notification off

    [profiles."lab"]
    host = "10.0.0.5"
    port = 7272
    user = "alice"
    remember_password = true
    auto_reconnect = true
    zoom = 0.5
    follow_robot = true
    show_sonar = true
    speed = 50

A profile may name a fleet instead of one robot: a list of robots reached
directly, or ARIA's central server that forwards them (``central``; a profile
with neither is the one robot of ``host``/``port``, as before)::

    [profiles."floor 2"]
    robots = [{ name = "robot1", host = "10.0.0.5", port = 7272 },
              { name = "robot2", host = "10.0.0.6", port = 7272 }]
    # or: central = "10.0.0.2:7272"
    connect_at_most = 20  # robots connected at once; the others are listed, connected when selected

It is read with ``tomllib`` and written by hand (the schema is flat, so no
writer library is needed), atomically, readable by the user only.

Rules:

* A password is **never** written to this file. With ``remember_password`` it
  goes to the desktop keyring (the ``keyring`` package, service ``rtmu``) —
  but only to a backend that keeps it encrypted (Secret Service, libsecret,
  KWallet, macOS Keychain, Windows Vault). Plain-text or file backends
  (``keyrings.alt`` and the like) are refused: then, as with no keyring at all,
  the operator is asked at connect time.
* A keyring call may block (D-Bus, an unlock prompt): the controller makes it
  off the UI thread when the link offers ``run_blocking``.
* A corrupt or foreign file never crashes RTMU: :func:`load_settings` returns
  the defaults plus **one** warning, and moves the bad file aside
  (``settings.toml.bad-<timestamp>``) so it is kept, not overwritten.
"""

from __future__ import annotations

import logging
import math
import os
import time
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from ..base.xdg import CONFIG, xdg_home
from .notifications import notification_lines, parse_notifications

log = logging.getLogger(__name__)

DEFAULT_PORT = 7272
SCHEMA_VERSION = 1
NEAR_PEOPLE_KEYS = ("near_people", "near_people_mm_s")
NEAR_PEOPLE_RANGE = (50, 1000)
"""mm/s a near-people cap may be set to in the settings file."""
MAX_SETTINGS_BYTES = 1 << 20
"""A settings file larger than this is not ours."""


MAX_FLEET = 100
CONNECT_AT_MOST = 20
"""A fleet's robots connected at once by default (``fleet.budget`` says why there is a bound)."""
MAX_CONNECT_AT_MOST = 1000
"""Robots one profile may list."""


@dataclass(frozen=True, slots=True)
class DirectRobot:
    """One robot of a fleet profile, reached directly."""

    name: str
    host: str
    port: int = DEFAULT_PORT

    def validate(self, profile: str) -> None:
        if not self.name or len(self.name) > 200:
            raise ValueError(f"profile {profile!r}: a robot name must be 1…200 characters")
        if not self.host or len(self.host) > 255:
            raise ValueError(f"profile {profile!r}: robot {self.name!r} has a bad host")
        if not 1 <= self.port <= 65535:
            raise ValueError(f"profile {profile!r}: robot {self.name!r}: port {self.port} is not 1…65535")


def parse_central(text: str) -> tuple[str, int]:
    """``"HOST:PORT"`` (or ``"HOST"``: ARIA's port) of a central server; ValueError when it is not one."""
    host, sep, port_text = text.rpartition(":")
    if not sep:
        host, port_text = text, str(DEFAULT_PORT)
    if not host or len(host) > 255 or not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise ValueError(f"central server {text!r} is not HOST:PORT")
    return host, int(port_text)


def address_name(host: str, port: int | str, user: str = "") -> str:
    """The name RTMU gives a profile made from an address: ``host:port``, ``user@host:port``."""
    user = user.strip()
    return f"{user + '@' if user else ''}{host.strip()}:{str(port).strip()}"


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
    """0 = fit the map."""
    follow_robot: bool = True
    show_sonar: bool = True
    speed: int = 50
    """Drive throttle in %, 10…100 in steps of 10."""
    protocol: str = ""
    """Protocol string to log in with; "" answers with the one the server advertises (LD robots: 6MTX)."""
    robots: tuple[DirectRobot, ...] = ()
    """A fleet of robots reached directly (names unique); empty: the one robot at host/port."""
    central: str = ""
    """``"HOST:PORT"`` of ARIA's central server that lists and forwards the robots; empty: none."""
    connect_at_most: int = CONNECT_AT_MOST
    """A fleet's robots connected at once (the others listed, connected when selected): 1…1000."""

    @property
    def is_fleet(self) -> bool:
        """The profile names several robots (a list or a central server), not one host."""
        return bool(self.robots or self.central)

    def validate(self) -> None:
        """Raise ValueError if a field is out of range (used on everything read from disk)."""
        if not self.name or len(self.name) > 200:
            raise ValueError("profile name must be 1…200 characters")
        if not self.host or len(self.host) > 255:
            raise ValueError(f"profile {self.name!r}: bad host")
        if not 1 <= self.port <= 65535:
            raise ValueError(f"profile {self.name!r}: port {self.port} is not 1…65535")
        if len(self.user) > 200:
            raise ValueError(f"profile {self.name!r}: user name too long")
        if len(self.protocol) > 200:
            raise ValueError(f"profile {self.name!r}: protocol string too long")
        if not (0.0 <= self.zoom <= 100.0) or math.isnan(self.zoom):
            raise ValueError(f"profile {self.name!r}: zoom {self.zoom} out of range")
        if not 10 <= self.speed <= 100 or self.speed % 10:
            raise ValueError(f"profile {self.name!r}: speed {self.speed} is not 10…100 in steps of 10")
        if len(self.robots) > MAX_FLEET:
            raise ValueError(f"profile {self.name!r}: more than {MAX_FLEET} robots")
        if not 1 <= self.connect_at_most <= MAX_CONNECT_AT_MOST:
            most = self.connect_at_most
            raise ValueError(f"profile {self.name!r}: connect_at_most {most} is not 1…{MAX_CONNECT_AT_MOST}")
        for robot in self.robots:
            robot.validate(self.name)
        names = [r.name for r in self.robots]
        if len(set(names)) != len(names):
            raise ValueError(f"profile {self.name!r}: two robots have the same name")
        if self.central:
            if self.robots:
                raise ValueError(f"profile {self.name!r}: name robots or a central server, not both")
            try:
                parse_central(self.central)
            except ValueError as exc:
                raise ValueError(f"profile {self.name!r}: {exc}") from None

    @property
    def keyring_user(self) -> str:
        """The keyring entry's user name: one password per (user, host, port)."""
        return f"{self.user}@{self.host}:{self.port}"


@dataclass(frozen=True, slots=True)
class RecordingSettings:
    """The flight recorder (``rtmu.recorder``): every connection of the window is written to an MCAP file.

    In the settings file as an optional table::

        [recording]
        enabled = true
        directory = ""        # "" = $XDG_DATA_HOME/rtmu/recordings
        max_file_mb = 1024    # one file stops growing here (the recording ends with a notice)
        keep_days = 30        # older recordings are deleted when a new one starts; 0 keeps all
    """

    enabled: bool = True
    directory: str = ""
    max_file_mb: int = 1024
    keep_days: int = 30

    def validate(self) -> None:
        if not 1 <= self.max_file_mb <= 1_000_000:
            raise ValueError(f"recording: max_file_mb {self.max_file_mb} is not 1…1000000")
        if not 0 <= self.keep_days <= 100_000:
            raise ValueError(f"recording: keep_days {self.keep_days} is not 0…100000")
        if len(self.directory) > 4096 or (self.directory and not os.path.isabs(self.directory)):
            raise ValueError("recording: directory must be an absolute path (or empty for the default)")


_RECORDING_TYPES: dict[str, type] = {"enabled": bool, "directory": str, "max_file_mb": int, "keep_days": int}

_TYPES: dict[str, type] = {
    "host": str,
    "port": int,
    "user": str,
    "remember_password": bool,
    "auto_reconnect": bool,
    "zoom": float,
    "follow_robot": bool,
    "show_sonar": bool,
    "speed": int,
    "protocol": str,
    "central": str,
    "connect_at_most": int,
}
_ROBOT_KEYS = {"name": str, "host": str, "port": int}


@dataclass
class Settings:
    profiles: dict[str, Profile] = field(default_factory=dict)
    last_profile: str | None = None
    recording: RecordingSettings = field(default_factory=RecordingSettings)
    alarms_muted: bool = False
    """The alarm sound is off (``alarms_muted = true``; the banners still show): the View menu's switch."""
    near_people: bool = False
    """Held driving is capped at :attr:`near_people_mm_s` (View → Near people)."""
    near_people_mm_s: int | None = None
    """Its speed (mm/s) when the operator chose one; None: the window's default (250 mm/s)."""
    notifications: dict[str, bool] = field(default_factory=dict)
    """Desktop notifications switched on or off by kind (``settings.notifications``); unnamed: on."""
    layers: dict[str, dict[str, bool]] = field(default_factory=dict)
    """The operator's drawing choices per server (``"host:port"`` → drawing name → shown), as the
    optional tables ``[layers."10.0.0.5:7272"]`` with ``"sonarCurrent" = false`` lines."""

    def current(self) -> Profile:
        """The profile used last, else the first one, else a default local one."""
        if self.last_profile in self.profiles:
            return self.profiles[self.last_profile]
        return next(iter(self.profiles.values()), Profile())

    def put(self, profile: Profile) -> None:
        """Add or replace a profile (by name) and make it the current one."""
        profile.validate()
        self.profiles[profile.name] = profile
        self.last_profile = profile.name

    def remove(self, name: str) -> None:
        self.profiles.pop(name, None)
        if self.last_profile == name:
            self.last_profile = None

    def remember_view(self, name: str, **view: Any) -> None:
        """Store the view options a profile was left with (``zoom``, ``follow_robot``, ``speed``…)."""
        old = self.profiles.get(name)
        if old is not None:
            self.put(replace(old, **view))


# -- where ------------------------------------------------------------------------------------


def config_dir(env: Mapping[str, str] | None = None) -> Path:
    """``$XDG_CONFIG_HOME/rtmu`` (an unset or relative value means ``~/.config``, as the spec says)."""
    return xdg_home(CONFIG, env) / "rtmu"


def settings_path(env: Mapping[str, str] | None = None) -> Path:
    return config_dir(env) / "settings.toml"


# -- read ------------------------------------------------------------------------------------


class SettingsError(ValueError):
    """The settings file is not one RTMU wrote (corrupt, foreign, or from a newer version)."""


def parse_settings(text: str) -> Settings:
    """Settings from TOML text; raises :class:`SettingsError` for anything unexpected."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SettingsError(f"not valid TOML: {exc}") from None
    version = doc.get("version", SCHEMA_VERSION)  # a hand-written file without the line: version 1
    if version != SCHEMA_VERSION:
        raise SettingsError(f"unknown settings version {version!r} (this RTMU writes {SCHEMA_VERSION})")
    known = {
        "version", "last_profile", "profiles", "recording", "alarms_muted", "layers", "notifications",
        *NEAR_PEOPLE_KEYS,
    }  # fmt: skip
    unknown = set(doc) - known
    if unknown:
        raise SettingsError(f"unknown settings: {', '.join(sorted(unknown))}")
    raw_profiles = doc.get("profiles", {})
    if not isinstance(raw_profiles, dict):
        raise SettingsError("'profiles' must be a table")
    settings = Settings()
    for name, raw in raw_profiles.items():
        if not isinstance(raw, dict):
            raise SettingsError(f"profile {name!r} must be a table")
        settings.profiles[name] = _profile(name, raw)
    last = doc.get("last_profile")
    if last is not None and not isinstance(last, str):
        raise SettingsError("'last_profile' must be a string")
    settings.last_profile = last if last in settings.profiles else None
    settings.recording = _recording(doc.get("recording", {}))
    muted = doc.get("alarms_muted", False)
    if type(muted) is not bool:
        raise SettingsError(f"alarms_muted must be true or false, not {muted!r}")
    settings.alarms_muted = muted
    near = doc.get("near_people", False)
    if type(near) is not bool:
        raise SettingsError(f"near_people must be true or false, not {near!r}")
    settings.near_people = near
    cap = doc.get("near_people_mm_s")
    if cap is not None and (type(cap) is not int or not NEAR_PEOPLE_RANGE[0] <= cap <= NEAR_PEOPLE_RANGE[1]):
        low, high = NEAR_PEOPLE_RANGE
        raise SettingsError(
            f"near_people_mm_s must be a whole number of mm/s from {low} to {high}, not {cap!r}"
        )
    settings.near_people_mm_s = cap
    settings.layers = _layers(doc.get("layers", {}))
    try:
        settings.notifications = parse_notifications(doc.get("notifications", {}))
    except ValueError as exc:
        raise SettingsError(str(exc)) from None
    return settings


MAX_LAYER_SERVERS = 256
MAX_LAYERS_PER_SERVER = 256


def _layers(raw: object) -> dict[str, dict[str, bool]]:
    if not isinstance(raw, dict) or len(raw) > MAX_LAYER_SERVERS:
        raise SettingsError(f"'layers' must be a table of at most {MAX_LAYER_SERVERS} servers")
    out: dict[str, dict[str, bool]] = {}
    for server, table in raw.items():
        if not isinstance(table, dict) or len(table) > MAX_LAYERS_PER_SERVER or len(server) > 300:
            raise SettingsError(
                f"layers: {server[:60]!r} must be a table of at most {MAX_LAYERS_PER_SERVER} names"
            )
        if not all(type(v) is bool and len(k) <= 255 for k, v in table.items()):
            raise SettingsError(f"layers: {server[:60]!r}: every value must be true or false")
        out[server] = dict(table)
    return out


def _recording(raw: object) -> RecordingSettings:
    if not isinstance(raw, dict):
        raise SettingsError("'recording' must be a table")
    values: dict[str, Any] = {}
    for key, value in raw.items():
        expected = _RECORDING_TYPES.get(key)
        if expected is None:
            raise SettingsError(f"recording: unknown key {key!r}")
        if type(value) is not expected:
            raise SettingsError(f"recording: {key} must be {expected.__name__}, not {value!r}")
        values[key] = value
    recording = RecordingSettings(**values)
    try:
        recording.validate()
    except ValueError as exc:
        raise SettingsError(str(exc)) from None
    return recording


def _profile(name: str, raw: dict[str, Any]) -> Profile:
    values: dict[str, Any] = {"name": name}
    for key, value in raw.items():
        if key == "robots":
            values[key] = _robots(name, value)
            continue
        expected = _TYPES.get(key)
        if expected is None:
            raise SettingsError(f"profile {name!r}: unknown key {key!r}")
        if expected is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if type(value) is not expected:
            raise SettingsError(f"profile {name!r}: {key} must be {expected.__name__}, not {value!r}")
        values[key] = value
    profile = Profile(**values)
    try:
        profile.validate()
    except ValueError as exc:
        raise SettingsError(str(exc)) from None
    return profile


def _robots(profile: str, raw: object) -> tuple[DirectRobot, ...]:
    """A profile's ``robots`` array of tables (each: name, host, port)."""
    if not isinstance(raw, list):
        raise SettingsError(f"profile {profile!r}: robots must be a list of tables")
    if len(raw) > MAX_FLEET:
        raise SettingsError(f"profile {profile!r}: more than {MAX_FLEET} robots")
    robots = []
    for item in raw:
        if not isinstance(item, dict) or set(item) - set(_ROBOT_KEYS) or not {"name", "host"} <= set(item):
            raise SettingsError(f"profile {profile!r}: each robot is a table of name, host and port")
        for key, value in item.items():
            if type(value) is not _ROBOT_KEYS[key]:
                raise SettingsError(f"profile {profile!r}: robot {key} must be {_ROBOT_KEYS[key].__name__}")
        robots.append(DirectRobot(**item))
    return tuple(robots)


@dataclass
class Loaded:
    settings: Settings
    warning: str | None = None
    """One operator-readable sentence when the file could not be used."""
    moved_to: Path | None = None


def load_settings(path: Path | None = None) -> Loaded:
    """Read the settings; never raises. Missing file → defaults, no warning."""
    path = path or settings_path()
    try:
        with path.open("rb") as f:
            data = f.read(MAX_SETTINGS_BYTES + 1)
    except FileNotFoundError:
        return Loaded(Settings())
    except OSError as exc:
        warning = f"could not read {path}: {exc.strerror or exc}; using default settings"
        log.warning(warning)
        return Loaded(Settings(), warning)
    try:
        if len(data) > MAX_SETTINGS_BYTES:
            raise SettingsError("the file is too large to be RTMU's")
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise SettingsError("the file is not UTF-8 text") from None
        settings = parse_settings(text)
        if not _says_its_version(text):
            note = (
                f"the settings file {path} has no 'version = {SCHEMA_VERSION}' line: it was read as version "
                f"{SCHEMA_VERSION} (RTMU writes the line when it next saves)"
            )
            return Loaded(settings, note)
        return Loaded(settings)
    except SettingsError as exc:
        moved = _set_aside(path)
        where = f"; it was kept as {moved.name}" if moved else ""
        warning = f"ignoring the settings file {path} ({exc}){where}; using default settings"
        log.warning(warning)
        return Loaded(Settings(), warning, moved)


def _says_its_version(text: str) -> bool:
    return "version" in tomllib.loads(text)


def _set_aside(path: Path) -> Path | None:
    """Rename a bad settings file so the next save cannot overwrite it."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for n in range(100):
        target = path.with_name(f"{path.name}.bad-{stamp}" + (f"-{n}" if n else ""))
        if target.exists():
            continue
        try:
            path.rename(target)
        except OSError:
            return None
        return target
    return None


# -- write -----------------------------------------------------------------------------------


def format_settings(settings: Settings) -> str:
    lines = ["# RTMU settings. Passwords are never stored here (see the desktop keyring).", ""]
    lines.append(f"version = {SCHEMA_VERSION}")
    if settings.last_profile is not None:
        lines.append(f"last_profile = {_toml_string(settings.last_profile)}")
    if settings.alarms_muted:
        lines.append("alarms_muted = true")
    if settings.near_people:
        lines.append("near_people = true")
    if settings.near_people_mm_s is not None:
        lines.append(f"near_people_mm_s = {int(settings.near_people_mm_s)}")
    for profile in settings.profiles.values():
        profile.validate()
        lines += ["", f"[profiles.{_toml_string(profile.name)}]"]
        for f in fields(profile):
            if f.name == "name" or (f.name in ("robots", "central") and not getattr(profile, f.name)):
                continue  # a one-robot profile is written as before the fleet existed
            if f.name == "connect_at_most" and profile.connect_at_most == CONNECT_AT_MOST:
                continue
            lines.append(f"{f.name} = {_toml_value(getattr(profile, f.name))}")
    if settings.recording != RecordingSettings():
        settings.recording.validate()
        lines += ["", "[recording]"]
        lines += [
            f"{f.name} = {_toml_value(getattr(settings.recording, f.name))}"
            for f in fields(settings.recording)
        ]
    lines += notification_lines(settings.notifications)
    for server, choices in settings.layers.items():
        if choices:
            lines += ["", f"[layers.{_toml_string(server)}]"]
            lines += [f"{_toml_string(name)} = {_toml_value(bool(on))}" for name, on in choices.items()]
    return "\n".join(lines) + "\n"


def save_settings(settings: Settings, path: Path | None = None) -> Path:
    """Write atomically (temp file + rename), mode 0600, creating the directory."""
    path = path or settings_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    text = format_settings(settings)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(float(value))
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, tuple) and all(isinstance(r, DirectRobot) for r in value):
        tables = [
            f"{{ name = {_toml_string(r.name)}, host = {_toml_string(r.host)}, port = {r.port} }}"
            for r in value
        ]
        return "[" + ", ".join(tables) + "]"
    raise TypeError(f"cannot write {value!r} to the settings file")


def _toml_string(text: str) -> str:
    out = ['"']
    for ch in text:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)
