"""``rtmu record`` loses nothing: an existing recording survives every failure, a limit ends it once,
and no recording holds what recovers a password.

Each runs the real command as a process against the simulator on loopback.
"""

from __future__ import annotations

import hashlib
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_SIZE_LIMIT, EXIT_USAGE
from rtmu.capture.recorded import RAW_TOPICS
from rtmu.protocol.commands import ClientCommand, ServerCommand
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.payloads.control import ClientIntroduction, ServerIntroduction
from rtmu.recorder import topics
from rtmu.sim import SimThread
from simulators import simulator

from .mcapread import read, summary_counts
from .simsession import ARENA

RTMU = [sys.executable, "-m", "rtmu"]
PASSWORD = "hunter2"


def rtmu(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*RTMU, *args], capture_output=True, text=True, timeout=timeout)


sim = simulator(scope="module", map_path=ARENA, seed=1, users=(f"alice {PASSWORD} all",))


@pytest.fixture
def secret(tmp_path: Path) -> Path:
    path = tmp_path / "pw"
    path.write_text(PASSWORD + "\n")
    return path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def record(sim_port: int, out: Path, secret: Path, *more: str) -> subprocess.CompletedProcess[str]:
    login = ("--user", "alice", "--password-file", str(secret), "--timeout", cli_timeout(5))
    return rtmu("record", f"127.0.0.1:{sim_port}", "--out", str(out), *login, *more)


@pytest.fixture
def old(tmp_path: Path) -> Path:
    """A recording somebody made before: 265 kB they want to keep."""
    path = tmp_path / "lab.mcap"
    path.write_bytes(b"an older recording " * 14_000)
    return path


def test_an_existing_recording_is_refused_without_force_before_connecting(old: Path, secret: Path) -> None:
    before = old.read_bytes()
    done = record(free_port(), old, secret, "--seconds", "1")  # nothing listens: it must not even try
    assert done.returncode == EXIT_USAGE, done.stderr
    assert "exists already; give --force" in done.stderr
    assert old.read_bytes() == before


@pytest.mark.parametrize("failure", ["wrong port", "wrong password"])
def test_a_failed_recording_with_force_leaves_the_old_one_whole(
    sim: SimThread, old: Path, secret: Path, tmp_path: Path, failure: str
) -> None:
    before = old.read_bytes()
    if failure == "wrong port":
        done = record(free_port(), old, secret, "--seconds", "1", "--force")
    else:
        secret.write_text("not the password\n")
        done = record(sim.port, old, secret, "--seconds", "1", "--force")
    assert done.returncode == EXIT_CONNECTION, done.stderr
    assert old.read_bytes() == before, "the old recording is untouched"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lab.mcap", "pw"], "nothing left beside it"


def test_a_good_recording_with_force_replaces_the_old_one_once_complete(
    sim: SimThread, old: Path, secret: Path
) -> None:
    done = record(sim.port, old, secret, "--seconds", "1.5", "--force")
    assert done.returncode == EXIT_OK, done.stderr
    assert summary_counts(old)[topics.STATUS] >= 1, "a finished recording took the old one's place"
    assert not old.with_name("lab.mcap.partial").exists()


def test_a_fresh_recording_is_written_beside_its_name_and_renamed_at_the_end(
    sim: SimThread, secret: Path, tmp_path: Path
) -> None:
    out = tmp_path / "new.mcap"
    leftover = tmp_path / "new.mcap.partial"  # a crashed run's file: kept, never overwritten
    leftover.write_bytes(b"crashed run")
    done = record(sim.port, out, secret, "--seconds", "1")
    assert done.returncode == EXIT_OK, done.stderr
    assert summary_counts(out)[topics.STATUS] >= 1
    assert leftover.read_bytes() == b"crashed run"
    assert not (tmp_path / "new.mcap.2.partial").exists()


def test_the_size_limit_is_said_once_ends_the_recording_and_has_its_code(
    sim: SimThread, secret: Path, tmp_path: Path
) -> None:
    out = tmp_path / "small.mcap"
    done = record(sim.port, out, secret, "--max-mb", "0.05", "--fps", "10", "--seconds", "120")
    assert done.returncode == EXIT_SIZE_LIMIT, done.stderr
    assert done.stderr.count("size limit") == 1, done.stderr
    assert "the recording ends here" in done.stderr
    assert read(out).counts()[RAW_TOPICS["s2c"]] > 0, "what came before the limit is kept"


def test_no_recording_holds_the_password_digest(sim: SimThread, secret: Path, tmp_path: Path) -> None:
    out = tmp_path / "shared-for-support.mcap"
    done = record(sim.port, out, secret, "--seconds", "1")
    assert done.returncode == EXIT_OK, done.stderr
    got = read(out)
    s2c = b"".join(m.data for m in got.topic(RAW_TOPICS["s2c"]))
    c2s = b"".join(m.data for m in got.topic(RAW_TOPICS["c2s"]))
    (server_intro,) = [p for p in PacketDecoder().feed(s2c) if p.command == ServerCommand.INTRODUCTION][:1]
    (client_intro,) = [p for p in PacketDecoder().feed(c2s) if p.command == ClientCommand.INTRODUCTION][:1]
    key = ServerIntroduction.decode(server_intro.payload).password_key
    digest = hashlib.md5((key + PASSWORD).encode()).digest()  # what an attacker would test guesses against
    intro = ClientIntroduction.decode(client_intro.payload)
    assert intro.user == "alice" and intro.password_digest == bytes(16)
    messages = b"".join(m.data for m in got.messages)
    assert digest not in messages and digest not in out.read_bytes()
    with out.open("rb") as f:
        metadata = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    assert any("zeroed" in values.get("login_digest", "") for values in metadata.values()), metadata
    decoded = rtmu("decode", "--json", str(out))
    assert decoded.returncode == 0 and '"checksum_ok":false' not in decoded.stdout
