"""Field encodings of protocol §1.5–1.6: exact bytes, round trips, underruns, text and doubles."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, ProtocolError
from rtmu.protocol.fields import (
    MAX_DOUBLE_TEXT,
    FieldReader,
    FieldWriter,
    format_double,
    parse_double,
)

# kind, size, smallest, largest
INT_KINDS = [
    ("byte", 1, -(2**7), 2**7 - 1),
    ("ubyte", 1, 0, 2**8 - 1),
    ("byte2", 2, -(2**15), 2**15 - 1),
    ("ubyte2", 2, 0, 2**16 - 1),
    ("byte4", 4, -(2**31), 2**31 - 1),
    ("ubyte4", 4, 0, 2**32 - 1),
    ("byte8", 8, -(2**63), 2**63 - 1),
    ("ubyte8", 8, 0, 2**64 - 1),
]
INT_IDS = [k[0] for k in INT_KINDS]


def write(kind: str, value: int) -> bytes:
    return getattr(FieldWriter(), kind)(value).bytes()


def read(kind: str, data: bytes, *args: object, **kwargs: object) -> object:
    return getattr(FieldReader(data), kind)(*args, **kwargs)


# -- integers ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "value", "wire"),
    [
        ("byte", -1, "ff"),
        ("byte", -128, "80"),  # updateNumbers' "temperature unknown"
        ("ubyte", 200, "c8"),
        ("byte2", 130, "8200"),  # 13.0 V battery × 10 from the §4.1 capture
        ("byte2", -2, "feff"),
        ("ubyte2", 0x0108, "0801"),
        ("ubyte2", 17272, "7843"),  # server UDP port of the §2.4 capture
        ("byte4", 200, "c8000000"),
        ("byte4", -1, "ffffffff"),
        ("ubyte4", 0x1E564427, "2744561e"),  # authKey of the §2.4 capture
        ("ubyte4", 0xFFFFFFFF, "ffffffff"),
        ("byte8", -2, "feffffffffffffff"),
        ("ubyte8", 0x0102030405060708, "0807060504030201"),
    ],
)
def test_integers_are_little_endian(kind: str, value: int, wire: str) -> None:
    assert write(kind, value) == bytes.fromhex(wire)
    assert read(kind, bytes.fromhex(wire)) == value


@pytest.mark.parametrize(("kind", "size", "lo", "hi"), INT_KINDS, ids=INT_IDS)
def test_integer_round_trip_over_the_whole_range(kind: str, size: int, lo: int, hi: int) -> None:
    @given(st.integers(lo, hi))
    def round_trip(value: int) -> None:
        data = write(kind, value)
        assert len(data) == size
        reader = FieldReader(data)
        assert getattr(reader, kind)() == value
        assert reader.at_end()

    round_trip()
    for edge in (lo, hi, 0):
        assert read(kind, write(kind, edge)) == edge


@pytest.mark.parametrize(("kind", "size", "lo", "hi"), INT_KINDS, ids=INT_IDS)
def test_integer_out_of_range_is_refused_when_writing(kind: str, size: int, lo: int, hi: int) -> None:
    for bad in (lo - 1, hi + 1):
        with pytest.raises(ValueError, match=kind):
            write(kind, bad)


@pytest.mark.parametrize(("kind", "size", "lo", "hi"), INT_KINDS, ids=INT_IDS)
def test_integer_underrun_names_the_field(kind: str, size: int, lo: int, hi: int) -> None:
    for available in range(size):
        with pytest.raises(FieldUnderrun) as info:
            read(kind, b"\x01" * available, "battery")
        assert info.value.field == "battery"
        assert info.value.needed == size
        assert info.value.remaining == available
        assert "battery" in str(info.value)
        assert isinstance(info.value, ProtocolError)


@pytest.mark.parametrize(("kind", "size", "lo", "hi"), INT_KINDS, ids=INT_IDS)
def test_integer_underrun_without_a_name_names_the_type(kind: str, size: int, lo: int, hi: int) -> None:
    with pytest.raises(FieldUnderrun, match=kind):
        read(kind, b"")


def test_default_gives_arias_leniency_for_optional_trailing_fields() -> None:
    """ratioDrive's latRatio may be missing: asked with a default, a short read yields it."""
    reader = FieldReader(b"\x05\x00\x01")
    assert reader.byte2("trans") == 5
    assert reader.byte2("rot", default=0) == 0  # 1 byte left: not enough, consumed, default
    assert reader.at_end()
    assert reader.byte4("lat", default=-7) == -7
    assert reader.string("text", default="") == ""
    assert reader.double("ratio", default=0.0) == 0.0


def test_reads_in_sequence_track_the_position() -> None:
    data = FieldWriter().ubyte2(300).string("abc").byte4(-5).raw(b"\x01\x02").bytes()
    reader = FieldReader(data)
    assert reader.remaining == len(data)
    assert reader.ubyte2() == 300
    assert reader.position == 2
    assert reader.string() == "abc"
    assert reader.byte4() == -5
    assert reader.rest() == b"\x01\x02"
    assert reader.at_end()
    assert reader.remaining == 0


def test_writer_length_and_chaining() -> None:
    writer = FieldWriter().byte(1).ubyte8(2).string("xy")
    assert len(writer) == 1 + 8 + 3
    assert writer.bytes() == b"\x01" + (2).to_bytes(8, "little") + b"xy\x00"


# -- strings ----------------------------------------------------------------------------------


def test_string_is_nul_terminated() -> None:
    assert FieldWriter().string("alpha").bytes() == b"alpha\x00"
    assert FieldWriter().string("").bytes() == b"\x00"
    assert FieldWriter().string(b"raw\xff").bytes() == b"raw\xff\x00"


def test_string_with_a_nul_is_refused() -> None:
    with pytest.raises(ValueError, match="NUL"):
        FieldWriter().string("a\x00b")


def test_text_outside_latin1_is_replaced_not_an_error() -> None:
    assert FieldWriter().string("naïve → ok").bytes() == "naïve ? ok".encode("latin-1") + b"\x00"


@given(st.binary(max_size=300).filter(lambda b: b"\x00" not in b))
def test_any_bytes_read_back_as_latin1_text(raw: bytes) -> None:
    """Text never raises on bad bytes: latin-1 maps every byte to one character."""
    reader = FieldReader(raw + b"\x00" + b"tail\x00")
    text = reader.string("name")
    assert text == raw.decode("latin-1")
    assert text.encode("latin-1") == raw
    assert reader.string() == "tail"


@given(st.text(alphabet=st.characters(max_codepoint=0xFF, blacklist_characters="\x00"), max_size=200))
def test_latin1_text_round_trips(text: str) -> None:
    assert FieldReader(FieldWriter().string(text).bytes()).string() == text


def test_unterminated_string_runs_to_the_payload_end() -> None:
    reader = FieldReader(b"Stopped\x00Sto")
    assert reader.string() == "Stopped"
    assert reader.string() == "Sto"
    assert reader.at_end()


def test_string_at_the_end_is_an_underrun_naming_the_field() -> None:
    reader = FieldReader(b"x\x00")
    reader.string()
    with pytest.raises(FieldUnderrun) as info:
        reader.string("mode")
    assert info.value.field == "mode"
    with pytest.raises(FieldUnderrun, match="string"):
        FieldReader(b"").string_bytes()


def test_string_default_comes_back_as_given() -> None:
    assert FieldReader(b"").string("name", default=None) is None
    assert FieldReader(b"").string("name", default="?") == "?"
    assert FieldReader(b"").string_bytes("name", default=b"") == b""


def test_empty_string_is_not_an_underrun() -> None:
    reader = FieldReader(b"\x00\x00")
    assert reader.string("first") == ""
    assert reader.string("second") == ""
    assert reader.at_end()


# -- fixed strings ------------------------------------------------------------------------------


def test_fixed_string_pads_and_truncates_like_strToBufPadded() -> None:
    assert FieldWriter().fixed_string("ab", 5).bytes() == b"ab\x00\x00\x00"
    assert FieldWriter().fixed_string("abcdefg", 4).bytes() == b"abcd"  # no terminator when full
    assert FieldWriter().fixed_string("", 3).bytes() == b"\x00\x00\x00"
    assert FieldWriter().fixed_string(b"\xe9t\xe9", 3).bytes() == b"\xe9t\xe9"


def test_fixed_string_reader_stops_at_the_first_nul_and_skips_the_padding() -> None:
    reader = FieldReader(b"ab\x00zz" + b"next\x00")
    assert reader.fixed_string(5, "label") == "ab"
    assert reader.string() == "next"
    assert FieldReader(b"abcd").fixed_string(4) == "abcd"


def test_fixed_string_underrun_names_the_field() -> None:
    with pytest.raises(FieldUnderrun) as info:
        FieldReader(b"abc").fixed_string(4, "robot name")
    assert info.value.field == "robot name"
    assert info.value.needed == 4
    assert info.value.remaining == 3


@given(st.binary(max_size=40), st.integers(0, 48))
def test_fixed_string_round_trip(raw: bytes, length: int) -> None:
    data = FieldWriter().fixed_string(raw, length).bytes()
    assert len(data) == length
    expected = raw[:length].split(b"\x00", 1)[0].decode("latin-1")
    assert FieldReader(data).fixed_string(length) == expected


# -- raw bytes --------------------------------------------------------------------------------


def test_raw_bytes_have_no_length_on_the_wire() -> None:
    digest = bytes(range(16))
    data = FieldWriter().raw(digest).raw(bytearray(b"\x01")).raw(memoryview(b"\x02")).bytes()
    assert data == digest + b"\x01\x02"
    reader = FieldReader(data)
    assert reader.raw(16, "password digest") == digest
    assert reader.raw(0) == b""
    assert reader.rest() == b"\x01\x02"
    assert reader.rest() == b""


def test_raw_underrun_names_the_field() -> None:
    with pytest.raises(FieldUnderrun) as info:
        FieldReader(b"\x00" * 15).raw(16, "password digest")
    assert info.value.field == "password digest"
    assert (info.value.needed, info.value.remaining) == (16, 15)
    with pytest.raises(FieldUnderrun):
        FieldReader(b"abc").raw(-1, "negative")


def test_reader_copies_its_input() -> None:
    buf = bytearray(b"abc\x00")
    reader = FieldReader(buf)
    buf[0] = ord("X")
    assert reader.string() == "abc"


# -- doubles as text --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (50.0, "50"),
        (0.0, "0"),
        (0.5, "0.5"),
        (100.0, "100"),
        (-12.25, "-12.25"),
        (1234567.0, "1.23457e+06"),
        (123456.0, "123456"),
        (1e-5, "1e-05"),
        (0.0001, "0.0001"),
        (-0.0, "-0"),
        (1e300, "1e+300"),
        (2.5e-310, "2.5e-310"),
        (math.inf, "INF"),
        (-math.inf, "-INF"),
    ],
)
def test_double_is_written_as_printf_g_text(value: float, text: str) -> None:
    assert format_double(value) == text
    assert FieldWriter().double(value).bytes() == text.encode() + b"\x00"


def test_nan_is_refused_when_writing() -> None:
    with pytest.raises(ValueError, match="NaN"):
        FieldWriter().double(math.nan)


def test_worked_example_c_payload() -> None:
    """ratioDrive 50, 0, 100, 0 of §1.3 example C."""
    data = FieldWriter().double(50).double(0).double(100).double(0).bytes()
    assert data == bytes.fromhex("35 30 00 30 00 31 30 30 00 30 00")
    reader = FieldReader(data)
    assert [reader.double() for _ in range(4)] == [50.0, 0.0, 100.0, 0.0]


@given(st.floats(allow_nan=False))
def test_double_round_trip_keeps_six_significant_digits(value: float) -> None:
    back = FieldReader(FieldWriter().double(value).bytes()).double()
    if math.isinf(value):
        assert back == value
    else:
        assert back == float("%g" % value)  # noqa: UP031 -- C printf semantics
        assert back == pytest.approx(value, rel=5e-6, abs=0)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("INF", math.inf),
        ("-INF", -math.inf),
        ("inf", math.inf),  # strtod's own spelling
        ("-Infinity", -math.inf),
        ("+INFINITY", math.inf),
        ("12", 12.0),
        ("-0.5", -0.5),
        ("+3", 3.0),
        (".5", 0.5),
        ("5.", 5.0),
        ("1.23457e+06", 1234570.0),
        ("1E3", 1000.0),
        ("  7", 7.0),  # strtod skips leading C whitespace
        ("\t\n\v\f\r8", 8.0),
        ("0x1p3", 8.0),  # hexadecimal floats
        ("-0X1.8p-1", -0.75),
        ("0x.8", 0.5),
        ("0x10", 16.0),
        ("1e999", math.inf),  # strtod saturates
        ("0x1p99999", math.inf),
        ("1e-999", 0.0),
        # not one whole number: ARIA's bufToDouble returns 0
        ("", 0.0),
        ("12abc", 0.0),
        ("abc", 0.0),
        ("7 ", 0.0),  # trailing whitespace is left unconsumed
        ("1_000", 0.0),  # Python's float() would accept this
        ("\xa05", 0.0),  # non-breaking space is not C whitespace
        ("\x1c5", 0.0),  # nor is a file separator (Python's str.isspace says yes)
        ("1e", 0.0),
        ("1e+", 0.0),
        ("0x", 0.0),
        ("1p3", 0.0),
        (".", 0.0),
        ("-", 0.0),
        ("infin", 0.0),
        ("INF ", 0.0),
        ("nan(", 0.0),
        ("1,5", 0.0),
        ("٣", 0.0),  # a Unicode digit; strtod knows only ASCII
    ],
)
def test_parse_double_follows_strtod_or_zero(text: str, value: float) -> None:
    assert parse_double(text) == value
    if value == 0.0 and text:
        assert not math.isnan(parse_double(text))


@pytest.mark.parametrize("text", ["nan", "NaN", "-nan", "nan(123_abc)"])
def test_parse_double_nan_spellings(text: str) -> None:
    assert math.isnan(parse_double(text))


@given(st.text(max_size=40))
def test_parse_double_never_raises(text: str) -> None:
    assert isinstance(parse_double(text), float)


@given(st.binary(max_size=300))
def test_double_reader_never_raises_on_any_text(raw: bytes) -> None:
    reader = FieldReader(raw.replace(b"\x00", b"") + b"\x00")
    assert isinstance(reader.double("x"), float)


def test_double_text_is_cut_at_255_characters_like_aria() -> None:
    """ARIA copies at most 255 characters of the text before strtod, then skips the rest."""
    long_number = "1" * MAX_DOUBLE_TEXT + "9"
    reader = FieldReader(long_number.encode() + b"\x00" + b"2\x00")
    assert reader.double() == float("1" * MAX_DOUBLE_TEXT)
    assert reader.double() == 2.0  # still aligned
    assert FieldReader(b"1" * 255 + b"x\x00").double() == float("1" * 255)  # the junk was cut off


def test_double_underrun_names_the_field() -> None:
    with pytest.raises(FieldUnderrun) as info:
        FieldReader(b"").double("throttle")
    assert info.value.field == "throttle"


# -- a reader never fails in any other way -----------------------------------------------------

READ_OPS = st.lists(
    st.sampled_from(
        [*INT_IDS, "string", "string_bytes", "double", "raw4", "fixed3", "rest", "at_end"],
    ),
    max_size=12,
)


@given(st.binary(max_size=64), READ_OPS)
def test_any_sequence_of_reads_on_any_bytes_returns_or_raises_field_underrun(
    data: bytes, ops: list[str]
) -> None:
    reader = FieldReader(data)
    for op in ops:
        before = reader.position
        try:
            if op == "raw4":
                reader.raw(4, op)
            elif op == "fixed3":
                reader.fixed_string(3, op)
            else:
                getattr(reader, op)()
        except FieldUnderrun as exc:
            assert exc.field
            assert reader.position == before, "a failed read must not move the position"
        assert 0 <= reader.position <= len(data)
