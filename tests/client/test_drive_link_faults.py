"""``rtmu drive`` through a fault-injecting proxy to the real simulator: it stops and says why, exit 5.

Each test drives for 20 s, applies one link fault, and checks what the simulator heard: the zero
ratios + ``stop`` (where the link still carries them) and only a handful of ``ratioDrive`` after the
fault — a blind drive would have sent ~180 more. No wall-clock limits: the counts say it.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Callable, Iterator

import pytest

from linkfaults import FAKE_HEADER, GARBAGE, TO_CLIENT, TO_SERVER, FaultProxy
from rtmu.base.exit_codes import EXIT_TIMEOUT
from rtmu.package_data import project_map
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.packet import encode_packet
from rtmu.sim import SimConfig, SimThread

from .uiqueue import eventually

ARENA = project_map("arena.map")
AFTER_FAULT_MAX = 8
"""ratioDrive packets the simulator may receive after the fault (already in flight + one resend
before the fault is seen); a blind drive sends ~10 a second until --seconds ends."""


@pytest.fixture
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=ARENA)) as s:
        yield s


@pytest.fixture
def proxy(sim: SimThread) -> Iterator[FaultProxy]:
    with FaultProxy("127.0.0.1", sim.port) as p:
        yield p


def _received(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))  # type: ignore[union-attr]


def _start_drive(sim: SimThread, proxy: FaultProxy) -> subprocess.Popen[str]:
    args = [sys.executable, "-m", "rtmu", "drive", f"127.0.0.1:{proxy.port}", "--trans", "60"]
    args += ["--seconds", "20", "--timeout", "5"]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline().startswith("before:")
    eventually(lambda: sim.snapshot().trans_ratio == 60, timeout=5)
    return proc


def _finish(proc: subprocess.Popen[str]) -> tuple[int, str]:
    try:
        code = proc.wait(15)
        return code, proc.stderr.read()  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


FAULTS: dict[str, tuple[Callable[[FaultProxy], float], str, bool]] = {
    # name: (apply, words the message must contain, can the stop reach the server)
    "mute_to_client": (lambda p: p.mute(TO_CLIENT), "no status", True),
    "mute_to_server": (lambda p: p.mute(TO_SERVER), "did not answer a ping", False),
    "mute_both": (lambda p: p.mute(TO_CLIENT, TO_SERVER), "", False),
    "rtt_800ms": (lambda p: p.delay(0.4), "", True),
    "reset": (lambda p: p.reset(), "lost the link", False),
}


@pytest.mark.parametrize("fault", list(FAULTS))
def test_drive_stops_on_link_fault_and_exits_5(sim: SimThread, proxy: FaultProxy, fault: str) -> None:
    apply, words, stop_arrives = FAULTS[fault]
    proc = _start_drive(sim, proxy)
    at_fault = _received(sim)
    apply(proxy)
    code, err = _finish(proc)
    assert code == EXIT_TIMEOUT, err
    assert err.startswith("rtmu drive: ") and err.count("\n") == 1, err
    assert words in err
    assert "stop sent" in err or "watchdog" in err
    if stop_arrives:
        snap = sim.snapshot
        eventually(lambda: snap().trans_ratio == 0 and snap().mode_name == "stop", timeout=5)  # ours…
        assert sim.snapshot().watchdog_stops == 0
    assert _received(sim) - at_fault <= AFTER_FAULT_MAX


@pytest.mark.parametrize("noise", [FAKE_HEADER, GARBAGE], ids=["fake_header", "garbage"])
def test_noise_never_leaves_the_drive_blind(sim: SimThread, proxy: FaultProxy, noise: bytes) -> None:
    """Bytes that are no packet: either they stall the stream (stop at once, exit 5) or the decoder
    skips them and status flows on — then driving on is right (a false stop is a defect too), and
    the drive still ends cleanly on request."""
    proc = _start_drive(sim, proxy)
    at_fault = _received(sim)
    proxy.inject(noise)
    try:
        code = proc.wait(3)
    except subprocess.TimeoutExpired:
        code = None
    if code is not None:  # the bytes cost the link: the drive must have stopped at once
        assert code == EXIT_TIMEOUT
        assert "no status" in proc.stderr.read()  # type: ignore[union-attr]
        assert sim.snapshot().trans_ratio == 0
        assert _received(sim) - at_fault <= AFTER_FAULT_MAX
        return
    # Still driving: right only if our decoder reads on past such bytes (status kept flowing).
    assert _decoder_reads_on_past(noise), "the stream stalled behind the noise, yet the drive went on"
    proc.send_signal(signal.SIGINT)
    assert _finish(proc)[0] == 128 + signal.SIGINT
    assert sim.snapshot().trans_ratio == 0


def _decoder_reads_on_past(noise: bytes) -> bool:
    """True when the project's decoder delivers status packets sent right after ``noise`` (3 s worth)."""
    status = encode_packet(1000, bytes(19))
    decoder = PacketDecoder()
    got = decoder.feed(status + noise)
    for _ in range(30):
        got += decoder.feed(status)
    return len(got) >= 25
