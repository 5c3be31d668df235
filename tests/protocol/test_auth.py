"""Password digest and ARIA's user-info file (protocol §2.5–2.6)."""

from __future__ import annotations

import hashlib
import random
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.auth import (
    PASSWORD_KEY_ALPHABET,
    User,
    UserFileError,
    UserTable,
    make_password_key,
    password_digest,
)

USERS = """\
UserInfoVersion1
; the example of the live tests in §2.6
user alice secret1 all
user bob pw2 RobotInfo Movement Stop
# a guest with no groups
user Guest guest
"""


def test_empty_digest_is_md5_of_nothing() -> None:
    """Captured from the real C++ client with no user, no password and no server key."""
    assert password_digest("", "", "").hex() == "d41d8cd98f00b204e9800998ecf8427e"


def test_digest_is_md5_of_server_key_password_key_password_in_that_order() -> None:
    digest = password_digest("secret1", "_yDK=p6JTRp0j_Iq6lNF1xs", "shared")
    assert digest == hashlib.md5(b"shared_yDK=p6JTRp0j_Iq6lNF1xssecret1").digest()
    assert len(digest) == 16
    assert (
        password_digest("secret1", "_yDK=p6JTRp0j_Iq6lNF1xs")
        == hashlib.md5(b"_yDK=p6JTRp0j_Iq6lNF1xssecret1").digest()
    )


@given(st.text(max_size=20), st.text(max_size=20), st.text(max_size=20))
def test_digest_never_raises_on_any_text(password: str, key: str, server_key: str) -> None:
    assert len(password_digest(password, key, server_key)) == 16


def test_password_key_is_drawn_from_arias_alphabet() -> None:
    assert PASSWORD_KEY_ALPHABET[0] == "0" and PASSWORD_KEY_ALPHABET[-1] == "y"
    assert len(PASSWORD_KEY_ALPHABET) == 0x7A - 0x30
    rng = random.Random(3)
    keys = [make_password_key(rng) for _ in range(200)]  # type: ignore[arg-type]
    assert all(16 <= len(k) <= 32 for k in keys)
    assert all(set(k) <= set(PASSWORD_KEY_ALPHABET) for k in keys)
    assert len(set(keys)) == len(keys)
    assert make_password_key(length=0) == ""
    assert len(make_password_key(length=99)) == 99
    assert set(make_password_key()) <= set(PASSWORD_KEY_ALPHABET)


def test_user_file_is_parsed() -> None:
    table = UserTable.parse(USERS)
    assert table is not None
    assert set(table.users) == {"alice", "bob", "guest"}
    assert table.users["bob"] == User("bob", "pw2", frozenset({"RobotInfo", "Movement", "Stop"}))
    assert table.users["guest"].groups == frozenset()


def test_do_not_use_disables_the_file() -> None:
    assert UserTable.parse("UserInfoVersion1\ndoNotUse\nuser alice secret1 all\n") is None


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("user alice secret1\n", "UserInfoVersion1"),
        ("UserInfoVersion1\nuser alice\n", ":2:"),
        ("UserInfoVersion1\nuser al-ice secret\n", ":2:"),
        ("UserInfoVersion1\nuser alice pass!word\n", ":2:"),
        ("UserInfoVersion1\n\nuser alice pass word!\npassword x\n", ":4:"),
    ],
)
def test_bad_user_files_say_where(text: str, where: str) -> None:
    with pytest.raises(UserFileError, match=where):
        UserTable.parse(text, "users.txt")


def test_user_file_is_loaded_as_latin1(tmp_path: Path) -> None:
    path = tmp_path / "users.txt"
    path.write_bytes(b"UserInfoVersion1\n; caf\xe9\nuser alice secret1 all\n")
    table = UserTable.load(path)
    assert table is not None and "alice" in table.users


def test_check_accepts_the_right_digest_with_any_name_case() -> None:
    table = UserTable.parse(USERS)
    assert table is not None
    key = "K3y"
    for name in ("alice", "ALICE", "Alice"):
        user = table.check(name, password_digest("secret1", key), key)
        assert user is not None and user.name == "alice"
    assert table.check("bob", password_digest("pw2", key, "srv"), key, "srv") is not None


@pytest.mark.parametrize(
    ("name", "password", "key_used", "server_key"),
    [
        ("alice", "wrong", "K3y", ""),  # wrong password
        ("carol", "secret1", "K3y", ""),  # unknown user
        ("alice", "secret1", "otherKey", ""),  # digest made for another connection
        ("alice", "secret1", "K3y", "srv"),  # server key on one side only
        ("al ice", "secret1", "K3y", ""),  # not alphanumeric
        ("alice\n", "secret1", "K3y", ""),
        ("", "", "K3y", ""),
    ],
)
def test_check_refuses(name: str, password: str, key_used: str, server_key: str) -> None:
    table = UserTable.parse(USERS)
    assert table is not None
    assert table.check(name, password_digest(password, key_used, server_key), "K3y") is None


def test_check_refuses_a_digest_of_the_wrong_size() -> None:
    table = UserTable.parse(USERS)
    assert table is not None
    assert table.check("alice", password_digest("secret1", "K")[:15], "K") is None


def test_groups() -> None:
    table = UserTable.parse(USERS)
    assert table is not None
    alice, bob, guest = table.users["alice"], table.users["bob"], table.users["guest"]
    assert alice.may_use("AnythingAtAll")
    assert bob.may_use("movement") and bob.may_use("Stop")
    assert not bob.may_use("Map")
    assert bob.may_use("")  # data without a command group is for everyone
    assert guest.may_use("") and not guest.may_use("Stop")
