"""Status packets decoded in bulk give, to the bit, what the packet decoder and the payload types give."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.robot import Update, UpdateNumbers
from rtmu.protocol.status_batch import StatusBatch, StatusStream, decode_status, walk

NUMBERS, UPDATE, OTHER = 0x0108, 0x0100, 0x0123
COMMANDS = {NUMBERS: "updateNumbers", UPDATE: "update"}

numbers = st.builds(
    UpdateNumbers,
    battery=st.integers(-32768, 32767).map(lambda tenths: tenths / 10),
    x=st.integers(-(2**31), 2**31 - 1),
    y=st.integers(-(2**31), 2**31 - 1),
    th=st.integers(-32768, 32767),
    vel=st.integers(-32768, 32767),
    rot_vel=st.integers(-32768, 32767),
    lat_vel=st.integers(-32768, 32767),
    temperature=st.integers(-128, 127),
)
text = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=20)
packets = st.one_of(
    numbers.map(lambda n: (NUMBERS, n.encode())),
    st.builds(Update, text, text, numbers).map(lambda u: (UPDATE, u.encode())),
    st.binary(max_size=60).map(lambda b: (OTHER, b)),
    numbers.map(lambda n: (NUMBERS, n.encode() + b"\x01\x02")),  # trailing bytes are ignored, as ARIA does
)


def by_packet_decoder(stream: bytes) -> list[tuple[int, UpdateNumbers | Update]]:
    decoder = PacketDecoder()
    out: list[tuple[int, UpdateNumbers | Update]] = []
    for packet in [*decoder.feed(stream), *decoder.close()]:
        if packet.command == NUMBERS:
            out.append((NUMBERS, UpdateNumbers.decode(packet.payload)))
        elif packet.command == UPDATE:
            out.append((UPDATE, Update.decode(packet.payload)))
    return out


def by_batch(stream: bytes) -> list[tuple[int, UpdateNumbers | Update]] | None:
    batch = decode_status(stream, COMMANDS)
    if batch is None:
        return None
    return [
        (int(c), batch.update_at(i) if c == UPDATE else batch.numbers_at(i))
        for i, c in enumerate(batch.command.tolist())
    ]


@settings(max_examples=300, deadline=None)
@given(st.lists(packets, max_size=40))
def test_a_clean_stream_decodes_as_the_payload_types_decode_it_and_encodes_back_the_same(
    items: list[tuple[int, bytes]],
) -> None:
    stream = b"".join(encode_packet(command, payload) for command, payload in items)
    got = by_batch(stream)
    assert got == by_packet_decoder(stream)
    status = [(c, p) for c, p in items if c in COMMANDS]
    assert got is not None and len(got) == len(status)
    for (command, payload), (_, value) in zip(status, got, strict=True):
        assert value.encode() == payload[: len(value.encode())]  # the same bytes (trailing ones aside)
        assert command == UPDATE or len(payload) - len(value.encode()) in (0, 2)


@settings(max_examples=300, deadline=None)
@given(st.lists(packets, min_size=1, max_size=20), st.data())
def test_a_damaged_stream_is_refused_or_decoded_exactly_as_the_packet_decoder_does(
    items: list[tuple[int, bytes]], data: st.DataObject
) -> None:
    stream = bytearray(b"".join(encode_packet(command, payload) for command, payload in items))
    where = data.draw(st.integers(0, len(stream) - 1))
    stream[where] ^= 1 << data.draw(st.integers(0, 7))
    got = by_batch(bytes(stream))
    if got is not None:  # a flip the checksum does not cover (ARIA skips an odd payload's last byte)
        assert got == by_packet_decoder(bytes(stream))


def test_a_status_packet_too_short_for_its_fields_is_refused() -> None:
    full = UpdateNumbers(12.5, 1, 2, 3, 4, 5, 6).encode()
    for cut in range(len(full)):
        assert decode_status(encode_packet(NUMBERS, full[:cut]), COMMANDS) is None
    assert decode_status(encode_packet(UPDATE, b"Stopped\0Stop"), COMMANDS) is None  # no second NUL
    assert decode_status(encode_packet(UPDATE, b"Stopped\0Stop\0" + full[:-1]), COMMANDS) is None


def test_an_unfinished_packet_ends_the_walk_where_the_whole_ones_end() -> None:
    one = encode_packet(NUMBERS, UpdateNumbers(12.5, 1, 2, 3, 4, 5, 6).encode())
    stream = one * 20 + one[:10]
    starts, end = walk(stream)
    assert starts == [i * len(one) for i in range(20)] and end == 20 * len(one)
    assert decode_status(stream, COMMANDS) is None and decode_status(stream[:end], COMMANDS) is not None


def rows_of(batch: StatusBatch | None) -> list[tuple[int, UpdateNumbers | Update]]:
    if batch is None:
        return []
    return [
        (int(c), batch.update_at(i) if c == UPDATE else batch.numbers_at(i))
        for i, c in enumerate(batch.command.tolist())
    ]


@settings(max_examples=200, deadline=None)
@given(
    st.lists(packets, min_size=1, max_size=300),
    st.lists(st.integers(1, 3000), min_size=1, max_size=8),
    st.lists(st.integers(0, 10**9), max_size=3),
)
def test_a_stream_fed_in_any_reads_gives_what_the_packet_decoder_gives(
    items: list[tuple[int, bytes]], reads: list[int], flips: list[int]
) -> None:
    """Read by read, damaged here and there: the same status values as the packet decoder and the
    payload types, in the same order (a damaged packet is lost to both alike)."""
    stream = bytearray(b"".join(encode_packet(command, payload) for command, payload in items))
    for flip in flips:
        stream[flip % len(stream)] ^= 1 << (flip % 8)
    data = bytes(stream)
    feed = StatusStream(COMMANDS, bulk_bytes=512)
    got: list[tuple[int, UpdateNumbers | Update]] = []
    pos = i = 0
    while pos < len(data):
        size = reads[i % len(reads)]
        got += rows_of(feed.feed(data[pos : pos + size]))
        pos, i = pos + size, i + 1
    got += rows_of(feed.close())
    assert got == by_packet_decoder(data)


def test_a_clean_stream_takes_the_bulk_path() -> None:
    items = [encode_packet(NUMBERS, UpdateNumbers(12.5, i, 2, 3, 4, 5, 6).encode()) for i in range(2000)]
    data = b"".join(items)
    feed = StatusStream(COMMANDS)
    batches = [feed.feed(data[k : k + 1448]) for k in range(0, len(data), 1448)]
    assert feed._slow is None  # never needed the packet decoder
    xs = [x for b in [*batches, feed.close()] if b is not None for x in b.numbers["x"].tolist()]
    assert xs == list(range(2000))
