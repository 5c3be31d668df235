"""The console's reading of a data's descriptions: argument types, reply fields, and "changes something".

Pure functions over ARIA's own description texts (the simulator's catalogue carries serverDemo's,
as captured) and hostile ones; no server needed.
"""

from __future__ import annotations

import time

import pytest

from rtmu.client.console_effect import Effect, classify, name_words
from rtmu.client.console_layout import (
    ArgumentError,
    describe,
    encode_arguments,
    parse_layout,
)
from rtmu.client.console_reply import MAX_FIELDS_SHOWN, split_fields, view_packet
from rtmu.protocol.datalist import DataEntry
from rtmu.protocol.fields import FieldReader, FieldWriter
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim.profiles import DEFAULT


def entry(name: str, description: str = "", flags: str = "RETURN_SINGLE") -> DataEntry:
    return DataEntry(256, name, description, flags=flags)


# -- argument layouts ----------------------------------------------------------------------------
def test_aria_argument_descriptions_give_their_types() -> None:
    catalogue = DEFAULT.catalogue(camera=True)
    gotopose = catalogue.entry("gotoPose")
    ratio = catalogue.entry("ratioDrive")
    assert gotopose is not None and ratio is not None
    layout = parse_layout(gotopose.argument_description)
    assert [f.kind for f in layout.fields] == ["byte4", "byte4", "byte4"]
    assert [f.optional for f in layout.fields] == [False, False, True]
    assert layout.required == 2
    ratios = parse_layout(ratio.argument_description)
    assert [f.kind for f in ratios.fields] == ["double"] * 4 and ratios.required == 3
    assert describe(ratios).endswith("[double lateralRatio (0,100)]")
    assert parse_layout("uByte2: width, uByte2: height").fields[1].kind == "ubyte2"
    for nothing in ("none", "None", "", "none (sent by the server only)"):
        layout = parse_layout(nothing)
        assert layout.known and not layout.fields, nothing


def test_a_description_without_types_is_unknown_and_wants_explicit_types() -> None:
    layout = parse_layout("Repeating pairs of strings which are parameter name and value")
    assert not layout.known
    with pytest.raises(ArgumentError, match="--type"):
        encode_arguments(layout, ["Teleop", "Timeout"])
    sent = encode_arguments(layout, ["Teleop", "7"], ["string", "byte4"])
    reader = FieldReader(sent)
    assert reader.string() == "Teleop" and reader.byte4() == 7 and reader.at_end()


def test_arguments_are_encoded_by_type_and_refused_when_they_do_not_fit() -> None:
    layout = parse_layout("byte4: x (mm); byte4: y (mm); optional byte4: heading (degrees)")
    reader = FieldReader(encode_arguments(layout, ["1000", "-2000"]))
    assert (reader.byte4(), reader.byte4(), reader.at_end()) == (1000, -2000, True)
    assert len(encode_arguments(layout, ["1", "2", "90"])) == 12
    with pytest.raises(ArgumentError, match="takes 2 arguments"):
        encode_arguments(layout, ["1"])
    with pytest.raises(ArgumentError, match="at most 3"):
        encode_arguments(layout, ["1", "2", "3", "4"])
    with pytest.raises(ArgumentError, match="not a whole number"):
        encode_arguments(layout, ["1.5", "2"])
    with pytest.raises(ArgumentError, match="outside"):
        encode_arguments(parse_layout("byte: 1 == on"), ["300"])
    with pytest.raises(ArgumentError, match="NaN"):
        encode_arguments(parse_layout("double: distance"), ["nan"])
    with pytest.raises(ArgumentError, match="latin-1"):
        encode_arguments(parse_layout("string: text"), ["snow ☃"])
    with pytest.raises(ArgumentError, match="unknown --type"):
        encode_arguments(parse_layout("none"), ["1"], ["float128"])
    assert FieldReader(encode_arguments(parse_layout("double: d"), ["-2.5"])).double() == -2.5


def test_a_repeating_group_takes_as_many_values_as_given() -> None:
    layout = parse_layout(
        "string: cameraName, repeating for each param: { string: paramName, string: value }"
    )
    assert layout.repeat_from == 1
    reader = FieldReader(encode_arguments(layout, ["cam", "a", "1", "b", "2"]))
    assert [reader.string() for _ in range(5)] == ["cam", "a", "1", "b", "2"]


def test_a_hostile_description_is_read_in_bounded_time() -> None:
    huge = "byte4: x; " * 100_000 + "(" * 50_000
    started = time.perf_counter()
    layout = parse_layout(huge)
    assert len(layout.fields) <= 64
    assert time.perf_counter() - started < 5  # generous: a bounded scan, not a figure


# -- reply fields ----------------------------------------------------------------------------------
def test_a_reply_is_split_as_its_return_description_says() -> None:
    catalogue = DEFAULT.catalogue(camera=True)
    numbers = catalogue.entry("updateNumbers")
    assert numbers is not None
    payload = UpdateNumbers(12.5, 1000, -2000, 90, 100, 5, 0, 25).encode()
    view = view_packet("updateNumbers", payload, parse_layout(numbers.return_description))
    assert [(f.kind, f.value) for f in view.fields[:4]] == [
        ("byte2", 125),
        ("byte4", 1000),
        ("byte4", -2000),
        ("byte2", 90),
    ]
    assert view.fields[1].label == "x"
    assert view.typed_name == "UpdateNumbers" and view.typed["x"] == 1000 and not view.typed_error
    assert view.hex.startswith("7d 00 e8 03")


def test_unknown_bytes_are_guessed_as_strings_doubles_and_integers() -> None:
    payload = FieldWriter().string("Docked").double(12.5).byte4(-7).byte2(3).ubyte(9).bytes()
    fields, more = split_fields(payload)
    assert [(f.kind, f.value) for f in fields] == [
        ("string", "Docked"),
        ("double", 12.5),
        ("byte4", -7),
        ("byte2", 3),
        ("ubyte", 9),
    ]
    assert more == 0


def test_a_hundred_thousand_fields_are_counted_not_made() -> None:
    payload = b"a\x00" * 100_000  # more than one packet holds: a reassembled or hostile buffer
    fields, more = split_fields(payload)
    assert len(fields) == MAX_FIELDS_SHOWN and len(fields) + more == 100_000
    described = parse_layout("<repeat> string: goal")
    fields, more = split_fields(payload, described)
    assert len(fields) == MAX_FIELDS_SHOWN and len(fields) + more == 100_000
    assert fields[0].label == "goal"


def test_a_known_type_that_does_not_decode_says_why() -> None:
    lying = FieldWriter().ubyte4(1_000_000_000).bytes() + b"\x01" * 20  # a count its bytes cannot hold
    view = view_packet("Laser_1Current", lying)
    assert view.typed_name and view.typed is None and "does not decode" in view.typed_error
    assert view.fields  # the bytes are still shown


# -- changes something ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name",
    [
        "setConfigValues",
        "updateConfigValues",
        "acknowledgeFault",
        "enableMotors",
        "stop",
        "dock",
        "gotoGoal",
        "deleteFile",
        "getAndResetCounters",
        "say",
        "popupClicked",
        "ratioDrive",
        "SimulatorSetBattery",
        "digitalOutputOn",
    ],
)
def test_names_that_change_something(name: str) -> None:
    effect, why = classify(entry(name))
    assert effect is Effect.CHANGES, why


@pytest.mark.parametrize(
    "name",
    [
        "getConfigValues",
        "configExpandedSectionList",
        "getFaults",
        "faultsUpdate",
        "queryMotors",
        "safetyStatusEStop",
        "safetyStatusSafetyLaser",
        "getBlockDriving",
        "DataStore_Laser_1_Zone",
        "DataStore_UserEstopCount",
        "dockInfo",
        "dockInfoChanged",
        "getSafeDrive",
        "updateNumbers",
        "update",
        "Laser_1Current",
        "getMapBinary",
        "sendVideo",
        "getPictureCam1",
    ],
)
def test_plain_reads(name: str) -> None:
    effect, why = classify(entry(name))
    assert effect is Effect.READ, why


def test_a_description_or_a_missing_reply_makes_an_unknown_name_a_change() -> None:
    assert classify(entry("frobnicate", "Sends the robot to the charger"))[0] is Effect.CHANGES
    assert classify(entry("frobnicate", flags="RETURN_NONE"))[0] is Effect.CHANGES
    effect, why = classify(entry("frobnicate"))
    assert effect is Effect.READ and "nothing" in why
    assert name_words("safetyStatusEStop") == ["safety", "status", "estop"]


def test_fields_run_together_without_separators_are_still_apart() -> None:
    """serverDemo's getSensorCurrent: "byte2: numReadings string: sensorName, …: byte4: x byte4: y"."""
    sensor = DEFAULT.catalogue(camera=True).entry("getSensorCurrent")
    assert sensor is not None
    layout = parse_layout(sensor.return_description)
    assert [f.kind for f in layout.fields] == ["byte2", "string", "byte4", "byte4"]
    assert layout.repeat_from == 2
    payload = FieldWriter().byte2(2).string("sonar").byte4(-2098).byte4(2377).byte4(10).byte4(-20).bytes()
    fields, more = split_fields(payload, layout)
    assert [(f.kind, f.value) for f in fields] == [
        ("byte2", 2),
        ("string", "sonar"),
        ("byte4", -2098),
        ("byte4", 2377),
        ("byte4", 10),
        ("byte4", -20),
    ]
    assert more == 0 and fields[4].label == "x"
