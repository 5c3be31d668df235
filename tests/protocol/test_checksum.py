"""The fast checksum must equal ARIA's per-byte loop (protocol §1.3) for every size and offset."""

from __future__ import annotations

import random

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.checksum import checksum, checksum_naive
from rtmu.protocol.packet import MAX_LENGTH


def body(hex_bytes: str) -> bytes:
    return bytes.fromhex(hex_bytes)


# Header + payload of the worked examples A–D of §1.3, with the checksum ARIA put on the wire.
WORKED_EXAMPLES = [
    pytest.param("0F 0C 0E 00 81 00 08 01 C8 00 00 00", 0x0251, id="A-even-payload"),
    pytest.param("0F 0C 0B 00 06 00 01 00 00", 0x0007, id="B-odd-payload"),
    pytest.param("0F 0C 13 00 17 01 35 30 00 30 00 31 30 30 00 30 00", 0xC24C, id="C-odd-text"),
    pytest.param("0F 0C 08 00 05 00", 0x0005, id="D-empty"),
    pytest.param("0F 0C 08 00 24 01", 0x0025, id="D-empty-data-number"),
]


@pytest.mark.parametrize(("hex_bytes", "expected"), WORKED_EXAMPLES)
def test_worked_examples(hex_bytes: str, expected: int) -> None:
    assert checksum(body(hex_bytes)) == expected
    assert checksum_naive(body(hex_bytes)) == expected


def test_every_payload_length_up_to_3000_matches_the_naive_loop() -> None:
    rng = random.Random(1234)
    for n in range(3001):
        data = rng.randbytes(6 + n)
        assert checksum(data) == checksum_naive(data), f"payload length {n}"


@pytest.mark.parametrize("length", [4, 5])
def test_shortest_inputs(length: int) -> None:
    data = bytes(range(1, length + 1))
    assert checksum(data) == checksum_naive(data)


@pytest.mark.parametrize("payload_length", [31990, 31991, 31992, 32 * 1024 - 8])
def test_32_kilobyte_packets(payload_length: int) -> None:
    rng = random.Random(payload_length)
    for _ in range(5):
        data = rng.randbytes(6 + payload_length)
        assert checksum(data) == checksum_naive(data)
    worst = b"\x0f\x0c" + b"\xff" * (4 + payload_length)  # every word 0xFFFF: the sum wraps many times
    assert checksum(worst) == checksum_naive(worst)


def test_largest_legal_packet_is_summed_by_both_paths_alike() -> None:
    data = random.Random(7).randbytes(MAX_LENGTH - 2)
    assert checksum(data) == checksum_naive(data)


@given(st.binary(min_size=6, max_size=2000), st.binary(max_size=40), st.binary(max_size=40))
def test_window_inside_a_larger_buffer(packet: bytes, before: bytes, after: bytes) -> None:
    """The decoder sums ``buf[start:end]`` in place; the result must not depend on the surroundings."""
    buf = bytearray(before + packet + after)
    start, end = len(before), len(before) + len(packet)
    assert checksum(buf, end, start) == checksum_naive(packet)
    assert checksum(memoryview(buf), end, start) == checksum_naive(packet)


@given(st.binary(min_size=6, max_size=4000))
def test_bytes_bytearray_and_memoryview_agree(data: bytes) -> None:
    expected = checksum_naive(data)
    assert checksum(data) == expected
    assert checksum(bytearray(data)) == expected
    assert checksum(memoryview(data)) == expected


def test_numpy_threshold_neighbourhood() -> None:
    """Sizes around the switch from ``struct`` to numpy, where an off-by-one would hide."""
    rng = random.Random(99)
    for n in range(480, 560):
        data = rng.randbytes(6 + n)
        assert checksum(data) == checksum_naive(data), n


def test_without_numpy_loaded_medium_packets_are_summed_with_struct(monkeypatch: pytest.MonkeyPatch) -> None:
    """A command that never loaded numpy (``rtmu status``, the guardian) sums a data list with
    ``struct``: the same checksum, around both switches (numpy's threshold and the struct limit)."""
    from types import SimpleNamespace

    from rtmu.protocol import checksum as module

    monkeypatch.setattr(module, "sys", SimpleNamespace(modules={}))
    rng = random.Random(7)
    limit = 2 * module._STRUCT_LIMIT
    for n in (*range(500, 530), 11_371, *range(limit - 12, limit + 12), MAX_LENGTH - 8):
        data = rng.randbytes(6 + n)
        assert checksum(data) == checksum_naive(data), n


def test_coverage_rules() -> None:
    """Bytes 0–2 are not covered; for an odd payload the last byte is not either (§1.3)."""
    even = bytearray.fromhex("0F 0C 0E 00 81 00 08 01 C8 00 00 00")
    odd = bytearray.fromhex("0F 0C 0B 00 06 00 01 00 00")
    for data in (even, odd):
        reference = checksum(data)
        for i in (0, 1, 2):
            changed = bytearray(data)
            changed[i] ^= 0x5A
            assert checksum(changed) == reference
    for i in range(3, len(even)):
        changed = bytearray(even)
        changed[i] ^= 0x01
        assert checksum(changed) != checksum(even), f"even payload: byte {i} must be covered"
    changed = bytearray(odd)
    changed[-1] = 0x01
    assert checksum(changed) == checksum(odd), "odd payload: the last byte is not covered"
    changed[-2] = 0x01
    assert checksum(changed) != checksum(odd)
