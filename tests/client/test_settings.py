"""Settings: profiles round-trip through TOML in a temp XDG_CONFIG_HOME; bad files never crash."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from rtmu.settings.secrets import KeyringSecrets, choose_backend, is_secure_backend
from rtmu.settings.store import (
    Profile,
    Settings,
    config_dir,
    format_settings,
    load_settings,
    parse_settings,
    save_settings,
    settings_path,
)


@pytest.fixture(autouse=True)
def xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    return tmp_path / "cfg"


def test_path_follows_xdg(xdg: Path) -> None:
    assert settings_path() == xdg / "rtmu" / "settings.toml"
    assert config_dir({"XDG_CONFIG_HOME": "relative/dir"}) == Path.home() / ".config" / "rtmu"
    assert config_dir({}) == Path.home() / ".config" / "rtmu"


def test_missing_file_gives_defaults_without_warning() -> None:
    loaded = load_settings()
    assert loaded.warning is None and loaded.settings.profiles == {}
    assert loaded.settings.current() == Profile()


def test_round_trip_with_awkward_names() -> None:
    s = Settings()
    s.put(Profile("lab", "10.0.0.5", 7272, "alice", remember_password=True, zoom=0.5, speed=30))
    s.put(
        Profile('robot "two"\\ü\t', "::1", 7000, follow_robot=False, show_sonar=False, auto_reconnect=False)
    )
    s.last_profile = "lab"
    path = save_settings(s)
    assert stat.S_IMODE(os.stat(path).st_mode) == 0o600
    loaded = load_settings()
    assert loaded.warning is None
    assert loaded.settings.profiles == s.profiles
    assert loaded.settings.current().name == "lab"


def test_no_password_is_ever_written() -> None:
    s = Settings()
    s.put(Profile("lab", user="alice", remember_password=True))
    text = format_settings(s)
    assert "\npassword" not in text and "secret" not in text


def test_view_options_are_remembered() -> None:
    s = Settings()
    s.put(Profile("lab"))
    s.remember_view("lab", zoom=0.8, speed=70, follow_robot=False)
    save_settings(s)
    p = load_settings().settings.profiles["lab"]
    assert (p.zoom, p.speed, p.follow_robot) == (0.8, 70, False)


@pytest.mark.parametrize(
    "content",
    [
        b"this is [not toml",
        b"\xff\xfe\x00garbage",
        b'version = 2\n[profiles.a]\nhost = "x"\n',
        b'version = 1\n[profiles.a]\nport = "7272"\n',
        b"version = 1\n[profiles.a]\nport = 99999\n",
        b"version = 1\n[profiles.a]\npassword = 'oops'\n",
        b'[core]\neditor = "vim"\n',  # somebody else's file
        b"version = 1\nprofiles = 3\n",
    ],
)
def test_corrupt_or_foreign_file_gives_defaults_one_warning_and_is_kept(content: bytes) -> None:
    path = settings_path()
    path.parent.mkdir(parents=True)
    path.write_bytes(content)
    loaded = load_settings()
    assert loaded.settings.profiles == {}
    assert loaded.warning is not None and "using default settings" in loaded.warning
    assert loaded.moved_to is not None and loaded.moved_to.read_bytes() == content
    # Saving the defaults afterwards does not touch the kept file.
    save_settings(loaded.settings)
    assert loaded.moved_to.read_bytes() == content
    assert load_settings().warning is None


def test_parse_rejects_unknown_keys() -> None:
    with pytest.raises(ValueError):
        parse_settings('version = 1\n[profiles.a]\ncolour = "red"\n')


class MemoryKeyring:
    """A keyring backend with the ``keyring`` package's three functions."""

    def __init__(self) -> None:
        self.store: dict[tuple[str, str], str] = {}

    def get_password(self, service: str, user: str) -> str | None:
        return self.store.get((service, user))

    def set_password(self, service: str, user: str, password: str) -> None:
        self.store[(service, user)] = password

    def delete_password(self, service: str, user: str) -> None:
        del self.store[(service, user)]


def test_keyring_secrets_store_per_user_host_port() -> None:
    backend = MemoryKeyring()
    secrets = KeyringSecrets(backend)
    p = Profile("lab", "10.0.0.5", 7272, "alice", remember_password=True)
    assert secrets.available and secrets.get(p) is None
    assert secrets.set(p, "secret1")
    assert backend.store == {("rtmu", "alice@10.0.0.5:7272"): "secret1"}
    assert secrets.get(p) == "secret1"
    secrets.forget(p)
    secrets.forget(p)
    assert secrets.get(p) is None


def test_without_a_keyring_nothing_is_stored_and_the_operator_is_asked() -> None:
    secrets = KeyringSecrets()
    if secrets.available:
        pytest.skip("a real keyring is installed here")
    p = Profile("lab", user="alice", remember_password=True)
    assert secrets.get(p) is None and secrets.set(p, "x") is False


def _backend(module: str, name: str) -> object:
    """An object whose class looks like keyring backend ``module.name``."""
    cls = type(name, (MemoryKeyring,), {"__module__": module})
    return cls()


def test_only_encrypted_keyring_backends_are_used(monkeypatch: pytest.MonkeyPatch) -> None:
    plaintext = _backend("keyrings.alt.file", "PlaintextKeyring")
    encrypted_file = _backend("keyrings.alt.file", "EncryptedKeyring")
    secret_service = _backend("keyring.backends.SecretService", "Keyring")
    assert is_secure_backend(secret_service)
    assert is_secure_backend(_backend("keyring.backends.kwallet", "DBusKeyring"))
    for bad in (plaintext, encrypted_file, _backend("keyring.backends.fail", "Keyring"),
                _backend("some.thirdparty", "Keyring")):  # fmt: skip
        assert not is_secure_backend(bad) and choose_backend(bad) is None
    chain = _backend("keyring.backends.chainer", "ChainerBackend")
    chain.backends = [plaintext, secret_service]  # type: ignore[attr-defined]
    assert choose_backend(chain) is secret_service  # a set can never fall through to plain text
    chain.backends = [plaintext]  # type: ignore[attr-defined]
    assert choose_backend(chain) is None
    # As the settings load it: a plain-text default backend means "no keyring".
    import keyring

    monkeypatch.setattr(keyring, "get_keyring", lambda: plaintext)
    secrets = KeyringSecrets()
    assert not secrets.available
    assert secrets.set(Profile("lab", user="alice", remember_password=True), "secret1") is False
    assert plaintext.store == {}  # type: ignore[attr-defined]
    monkeypatch.setattr(keyring, "get_keyring", lambda: secret_service)
    assert KeyringSecrets().available


def test_a_hand_written_file_without_its_version_line_is_read_as_version_1_and_said() -> None:
    """The README's fleet example had no version line: the file was moved aside and defaults used."""
    path = settings_path()
    path.parent.mkdir(parents=True)
    text = '[profiles.fleet]\nrobots = [{ name = "robot1", host = "10.0.0.5", port = 7272 }]\n'
    path.write_text(text)
    loaded = load_settings()
    assert "fleet" in loaded.settings.profiles and loaded.moved_to is None
    assert loaded.warning is not None and "read as version 1" in loaded.warning  # the window's banner
    assert path.read_text() == text, "the operator's file is left as it is"
    save_settings(loaded.settings)
    assert "\nversion = 1\n" in path.read_text() and load_settings().warning is None
