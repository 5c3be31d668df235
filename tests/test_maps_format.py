"""The .map format rule by rule: header keywords, objects, quoting, data sections, multi-scan maps, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.mapfile import (
    InfoLine,
    MapData,
    MapFormatError,
    MapObject,
    MapScan,
    from_stream,
    info_fields,
    map_bytes,
    map_lines,
    new_map,
    parse_map,
    parse_map_lines,
    split_tokens,
)

FULL_HEADER = """2D-Map-Ex2
Sources: SickLaser Sonar
Display: "Laser scan"
MinPos: -1000 -500
MaxPos: 3000 2000
NumPoints: 3
PointsAreSorted: false
Resolution: 100
LineMinPos: 0 0
LineMaxPos: 3000 2000
NumLines: 2
LinesAreSorted: true
SonarDisplay: "Sonar echoes"
SonarMinPos: 10 20
SonarMaxPos: 30 40
SonarNumPoints: 2
SonarPointsAreSorted: true
SonarResolution: 50
OriginLatLongAlt: 42.807191 -71.578661 72.000000
MapInfo: SectorType Name=SlowZone "Label=Slow zone" "Desc=Drive slowly here" Shape=Plain Color0=0x00aa00
MapInfo: GoalType Name=Goal
MetaInfo: Author "Jo Bloggs"
TaskInfo: Task1 x
RouteInfo: Route1
SchedTaskInfo: a
SchedInfo: b
CairnInfo: Params Goal "Speed=100"
CustomInfo: Custom1 a=b
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
Cairn: ForbiddenLine 0 0 0.000000 "" ICON "" 0 0 3000 0
Cairn: Goal 1500 1000 0.000000 "" ICON "Kitchen ; # not a comment"
Cairn: GoalWithHeading 2500 500 90.000000 "" ICON "Front door"
Cairn: ForbiddenArea 0 0 0.000000 "" ICON "" 1200 200 1800 900
Cairn: SlowZone 0 0 30.000000 "" ICON "Hall" -200 -200 200 200
_MapInfo: GoalType Name=OldGoal
_Cairn: Goal 5 5 0.000000 "" ICON "Retired"
ChildCairn: Goal 6 6 0.000000 "" ICON "Child"
Frobnicate: 1 2 3
; a line that ARIA would not treat as a comment
LINES
0 0 3000 0
3000 0 3000 2000
Sonar_LINES
1 2 3 4
DATA
-1000 -500
0 0
3000 2000
Sonar_DATA
10 20
30 40
"""


@pytest.fixture(scope="module")
def full() -> MapData:
    return parse_map(FULL_HEADER, source="full.map")


def test_every_scan_keyword(full: MapData) -> None:
    laser, sonar = full.scans
    assert full.category == "2D-Map-Ex2"
    assert (laser.name, laser.prefix, sonar.name, sonar.prefix) == ("SickLaser", "", "Sonar", "Sonar")
    assert laser.display == "Laser scan" and sonar.display == "Sonar echoes"
    assert laser.claimed.min_pos == (-1000, -500) and laser.claimed.max_pos == (3000, 2000)
    assert laser.claimed.num_points == 3 and laser.claimed.num_lines == 2
    assert laser.claimed.line_min_pos == (0, 0) and laser.claimed.line_max_pos == (3000, 2000)
    assert laser.resolution == 100 and sonar.resolution == 50
    assert (laser.points_sorted, laser.lines_sorted, sonar.points_sorted) == (False, True, True)
    assert sonar.claimed.min_pos == (10, 20) and sonar.claimed.num_points == 2
    assert laser.points.tolist() == [[-1000, -500], [0, 0], [3000, 2000]]
    assert laser.segments.tolist() == [[0, 0, 3000, 0], [3000, 0, 3000, 2000]]
    assert sonar.segments.tolist() == [[1, 2, 3, 4]]
    assert sonar.points.tolist() == [[10, 20], [30, 40]]


def test_info_objects_and_kept_lines(full: MapData) -> None:
    assert full.origin_lat_long_alt == (42.807191, -71.578661, 72.0)
    keywords = [line.keyword for line in full.info]
    assert keywords == [
        "MapInfo",
        "MapInfo",
        "MetaInfo",
        "TaskInfo",
        "RouteInfo",
        "SchedTaskInfo",
        "SchedInfo",
        "CairnInfo",
        "CustomInfo",
        "_MapInfo",
    ]
    assert full.map_info[0].startswith('SectorType Name=SlowZone "Label=Slow zone"')
    assert info_fields(full.map_info[0]) == (
        "SectorType",
        {
            "Name": "SlowZone",
            "Label": "Slow zone",
            "Desc": "Drive slowly here",
            "Shape": "Plain",
            "Color0": "0x00aa00",
        },
    )
    assert full.inactive_objects == ['Goal 5 5 0.000000 "" ICON "Retired"']
    assert full.child_objects == ['Goal 6 6 0.000000 "" ICON "Child"']
    assert full.unknown_lines == ["Frobnicate: 1 2 3", "; a line that ARIA would not treat as a comment"]
    assert full.goal_names() == ["Kitchen ; # not a comment", "Front door"]
    slow = full.objects_of_type("slowzone")[0]
    assert slow == MapObject("SlowZone", 0, 0, 30.0, "", "ICON", "Hall", (-200, -200), (200, 200))
    line = full.objects_of_type("ForbiddenLine")[0]
    assert line.has_from_to and line.from_xy == (0, 0) and line.to_xy == (3000, 0)
    assert full.objects_of_type("GoalWithHeading")[0].base_type == "Goal"


def test_full_round_trip_and_writer_order(full: MapData) -> None:
    text = map_bytes(full).decode("latin-1")
    again = parse_map(text)
    assert again == full
    lines = text.splitlines()
    assert lines[:3] == ["2D-Map-Ex2", "Sources: SickLaser Sonar", 'Display: "Laser scan"']
    order = [
        lines.index(x)
        for x in (
            "MinPos: -1000 -500",
            "SonarMinPos: 10 20",
            "OriginLatLongAlt: 42.807191 -71.578661 72.000000",
            "MapInfo: GoalType Name=Goal",
            'MetaInfo: Author "Jo Bloggs"',
            "CustomInfo: Custom1 a=b",
            'Cairn: RobotHome 0 0 0.000000 "" ICON "Home"',
            "_MapInfo: GoalType Name=OldGoal",
            '_Cairn: Goal 5 5 0.000000 "" ICON "Retired"',
            'ChildCairn: Goal 6 6 0.000000 "" ICON "Child"',
            "Frobnicate: 1 2 3",
            "LINES",
            "Sonar_LINES",
            "DATA",
            "Sonar_DATA",
        )
    ]
    assert order == sorted(order)
    assert "SonarLineMinPos: 1 2" in lines and "SonarNumLines: 1" in lines  # recomputed, not copied


def test_counts_and_bounds_are_recomputed_when_written() -> None:
    data = parse_map("2D-Map\nNumPoints: 7\nMinPos: 9 9\nMaxPos: 9 9\nDATA\n1 2\n-5 8\n")
    lines = map_lines(data)
    assert "NumPoints: 2" in lines and "MinPos: -5 2" in lines and "MaxPos: 1 8" in lines


def test_minimal_map_and_empty_map_written() -> None:
    data = parse_map("2d-map\nDATA\n")
    assert data.category == "2D-Map" and data.num_points == 0 and data.num_lines == 0
    assert data.bounds() is None and data.home() is None
    assert map_lines(MapData()) == ["2D-Map", "DATA"]


@pytest.mark.parametrize("category", ["2D-Map", "2d-map", "2D-MAP-EX", "2D-Map-Ex2", "2d-map-ex3"])
def test_categories_case_insensitive(category: str) -> None:
    data = parse_map(f"\n  \n{category}\nDATA\n")
    assert data.category.lower() == category.lower()
    assert data.category in ("2D-Map", "2D-Map-Ex", "2D-Map-Ex2", "2D-Map-Ex3")


def test_keywords_case_insensitive_and_blank_lines_and_cr() -> None:
    lines = [
        "2D-Map",
        "",
        "numpoints: 2",
        "   ",
        "RESOLUTION: 20",
        'cairn: Goal 1 2 3 "" ICON "A"',
        "data",
        "1 2",
        "",
        "3 4",
    ]
    text = "\r\n".join(lines) + "\r\n"
    data = parse_map(text)
    assert data.claimed.num_points == 2 and data.resolution == 20
    assert data.goal_names() == ["A"]
    assert data.points.tolist() == [[1, 2], [3, 4]]
    assert data.skipped_lines == 0


@pytest.mark.parametrize("tag", ["DATA", "data", "DATAxyz", "Data and more"])
def test_data_tags_match_by_prefix_in_the_data_part(tag: str) -> None:
    data = parse_map(f"2D-Map\nLINES\n0 0 1 1\n{tag}\n5 6\n")
    assert data.segments.tolist() == [[0, 0, 1, 1]]
    assert data.points.tolist() == [[5, 6]]


@pytest.mark.parametrize("tag", ["lines", "LINESabc"])
def test_lines_tag_matches_by_prefix_after_data(tag: str) -> None:
    data = parse_map(f"2D-Map\nDATA\n5 6\n{tag}\n0 0 1 1\ndata\n7 8\n")
    assert data.segments.tolist() == [[0, 0, 1, 1]]
    assert data.points.tolist() == [[5, 6], [7, 8]]


def test_scan_tags_without_sources_are_garbage() -> None:
    data = parse_map("2D-Map\nDATA\n1 2\nSonar_DATA\n3 4\n")
    assert data.points.tolist() == [[1, 2], [3, 4]]
    assert data.skipped_lines == 1
    assert data.warnings[0].line == 4


def test_quoted_tokens() -> None:
    assert split_tokens('Goal 1 2 3 "" ICON "Kitchen  door"') == [
        "Goal",
        "1",
        "2",
        "3",
        '""',
        "ICON",
        '"Kitchen  door"',
    ]
    assert split_tokens('" a b " x') == ['" a b "', "x"]
    data = parse_map('2D-Map\nCairn: Goal 1 2 0 "" ICON "Lab  B #2"\nCairn: Goal 3 4 0 "" ICON Plain\nDATA\n')
    assert data.goal_names() == ["Lab  B #2", "Plain"]
    assert 'Cairn: Goal 3 4 0.000000 "" ICON "Plain"' in map_lines(data)


def test_cairn_description_token_and_extra_fields() -> None:
    data = parse_map(
        "2D-Map\n"
        'Cairn: Goal 1 2 0 "" ICON "A" "later description"\n'
        'Cairn: ForbiddenLine 0 0 0 "" ICON "" 1 2 3 4 "desc" extra stuff\n'
        "DATA\n"
    )
    goal, line = data.objects
    assert goal.description == "later description"
    assert line.description == "desc" and line.to_xy == (3, 4)
    assert data.warning_count == 1 and data.warnings[0].line == 3
    again = parse_map(map_bytes(data))
    assert again.objects == data.objects


def test_object_numbers_round_trip_exactly() -> None:
    obj = MapObject("GoalWithHeading", 1.5, -2, 12.3456789, "d", "ICON", "n")
    data = new_map(objects=[obj])
    assert parse_map(map_bytes(data)).objects == [obj]
    assert 'Cairn: GoalWithHeading 1.5 -2 12.3456789 "d" ICON "n"' in map_lines(data)


def test_cairn_with_custom_type_and_icon() -> None:
    data = parse_map('2D-Map\nCairn: Docking 10 20 -45 "desc" ID=3 "Dock A"\nDATA\n')
    obj = data.objects[0]
    assert (obj.type, obj.icon, obj.description, obj.th) == ("Docking", "ID=3", "desc", -45.0)
    assert not obj.is_goal


def test_quotes_inside_a_name_survive_when_they_can() -> None:
    data = parse_map('2D-Map\nCairn: Goal 1 2 0 "" ICON "Bob"s desk"\nDATA\n')
    assert data.goal_names() == ['Bob"s desk']
    assert parse_map(map_bytes(data)) == data


def test_latin1_names() -> None:
    data = parse_map('2D-Map\nCairn: Goal 1 2 0 "" ICON "Küche"\nDATA\n'.encode("latin-1"))
    assert data.goal_names() == ["Küche"]
    assert b'"K\xfcche"' in map_bytes(data)


# -- errors and warnings ------------------------------------------------------------------------------


def _error(text: str | bytes) -> MapFormatError:
    with pytest.raises(MapFormatError) as info:
        parse_map(text, source="bad.map")
    return info.value


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("2D-Mapp\nDATA\n", 1, "not an ARIA map"),
        ("\n\nLINES\n", 3, "not an ARIA map"),
        ("MinPos: 1 2\n2D-Map\nDATA\n", 1, "not an ARIA map"),
        ("2D-Map\nMinPos: 1 2\nCairn: Goal 1 2", 3, "Cairn"),
        ("2D-Map\nMinPos: 1 2\n", 2, "truncated"),
        ("2D-Map\nMinPos: 1\nDATA\n", 2, "MinPos"),
        ("2D-Map\nNumPoints: many\nDATA\n", 2, "NumPoints"),
        ("2D-Map\nNumLines: -3\nDATA\n", 2, "NumLines"),
        ("2D-Map\nPointsAreSorted: maybe\nDATA\n", 2, "PointsAreSorted"),
        ("2D-Map\nOriginLatLongAlt: 1 2\nDATA\n", 2, "OriginLatLongAlt"),
        ('2D-Map\nCairn: Goal 1 2 0 "" ICON\nDATA\n', 2, "7 fields"),
        ('2D-Map\nCairn: Goal x 2 0 "" ICON "A"\nDATA\n', 2, "numbers"),
        ('2D-Map\nCairn: Goal nan 2 0 "" ICON "A"\nDATA\n', 2, "numbers"),
        ('2D-Map\nCairn: Goal 1 2 0 "" ICON "Kitchen\nDATA\n', 2, "unterminated quote"),
        ('2D-Map\nCairn: ForbiddenLine 0 0 0 "" ICON "" 1 2 3 y\nDATA\n', 2, "x1 y1 x2 y2"),
        ('2D-Map\nCairn: ForbiddenArea 0 0 0 "" ICON "" 1 2\nDATA\n', 2, "end points"),
        ('2D-Map\nMapInfo: BoundaryType Name=Wall\nCairn: Wall 0 0 0 "" ICON ""\nDATA\n', 3, "end points"),
        ("2D-Map-Ex\nSources: A B\nSources: C\nDATA\n", 3, "second Sources"),
        ("2D-Map-Ex\nSources: A a\nDATA\n", 2, "twice"),
    ],
)
def test_malformed_maps_name_file_and_line(text: str, line: int, words: str) -> None:
    error = _error(text)
    assert error.source == "bad.map"
    assert error.line == line
    assert words in str(error)
    assert str(error).startswith(f"bad.map:{line}: ")


def test_lenient_where_aria_is() -> None:
    text = '2D-Map extra\nResolution: 20.0\nNumPoints: 1e1\nMapInfo: BoundaryType "Name=Odd\nDATA\n'
    data = parse_map(text)
    assert data.resolution == 20 and data.claimed.num_points == 10
    assert data.map_info == ['BoundaryType "Name=Odd']
    assert data.warning_count == 1 and "extra" in data.warnings[0].message and data.skipped_lines == 0
    with pytest.raises(MapFormatError, match="whole number"):
        parse_map("2D-Map\nResolution: 20.5\nDATA\n")


def test_empty_input() -> None:
    assert "empty" in str(_error(""))
    assert "empty" in str(_error("\n \n"))
    with pytest.raises(MapFormatError, match="no map"):
        parse_map_lines([])


def test_garbage_in_data_is_skipped_and_counted() -> None:
    text = (
        "2D-Map\nLINES\n1 2 3 4\n1 2 3\nwall\n5 6 7 8 9\n"
        "DATA\n1 2\nx y\n1.5 2\n3 4 ; note\n\n5 6\n99999999999 1\n7"
    )
    data = parse_map(text, source="g.map")
    assert data.segments.tolist() == [[1, 2, 3, 4]]
    assert data.points.tolist() == [[1, 2], [5, 6]]
    assert data.skipped_lines == 8
    assert [w.line for w in data.warnings] == [4, 5, 6, 9, 10, 11, 14, 15]
    assert "'x y'" in data.warnings[3].message


def test_truncated_last_data_line() -> None:
    whole = parse_map("2D-Map\nDATA\n1 2\n3 4\n")
    cut = parse_map("2D-Map\nDATA\n1 2\n3")
    assert cut.points.tolist() == [[1, 2]] and cut.skipped_lines == 1 and cut.warnings[0].line == 4
    assert whole.points.tolist() == [[1, 2], [3, 4]] and whole.skipped_lines == 0


def test_malformed_digit_tokens_take_the_careful_path() -> None:
    data = parse_map("2D-Map\nDATA\n1 2\n1-2 3\n- 4\n+5 -6\n--1 2\n")
    assert data.points.tolist() == [[1, 2], [5, -6]]
    assert [w.line for w in data.warnings] == [4, 5, 7]


def test_warnings_kept_are_bounded() -> None:
    data = parse_map("2D-Map\nDATA\n" + "junk\n" * 5000 + "1 2\n")
    assert data.skipped_lines == 5000 and data.warning_count == 5000
    assert len(data.warnings) == 100
    assert data.points.tolist() == [[1, 2]]


def test_lines_with_line_breaks_are_refused() -> None:
    with pytest.raises(MapFormatError, match="line break"):
        parse_map_lines(["2D-Map", "DATA\n1 2"])
    with pytest.raises(MapFormatError, match="latin-1"):
        parse_map_lines(["2D-Map", 'Cairn: Goal 1 2 0 "" ICON "\u20ac"', "DATA"])


def test_writer_refuses_what_cannot_be_read_back() -> None:
    with pytest.raises(ValueError, match="read back"):
        map_bytes(new_map(objects=[MapObject("Goal", 0, 0, name='a" b')]))
    with pytest.raises(ValueError, match="unknown header line"):
        map_bytes(MapData(unknown_lines=["data"]))
    with pytest.raises(ValueError, match="unknown header line"):
        map_bytes(MapData(unknown_lines=["   "]))
    with pytest.raises(ValueError, match="one word"):
        map_bytes(new_map(objects=[MapObject("Big Goal", 0, 0)]))
    with pytest.raises(ValueError, match="latin-1"):
        map_bytes(new_map(objects=[MapObject("Goal", 0, 0, name="\u20ac")]))
    with pytest.raises(ValueError, match="category"):
        map_bytes(MapData(category="3D-Map"))
    with pytest.raises(ValueError, match="line break"):
        map_bytes(MapData(unknown_lines=["a\nb"]))
    with pytest.raises(ValueError, match="from_xy and to_xy"):
        MapObject("ForbiddenLine", 0, 0, from_xy=(1, 2))
    with pytest.raises(ValueError, match="shape"):
        new_map(points=[[1, 2, 3]])
    with pytest.raises(ValueError, match="32-bit"):
        new_map(points=[[2**31, 0]])


def test_from_stream_checks_arrays_and_scans() -> None:
    header = ["2D-Map-Ex", "Sources: SickLaser Sonar", 'Cairn: RobotHome 1 2 3 "" ICON "Home"']
    data = from_stream(header, [[0, 0, 5, 5]], np.array([[1, 1]]), scans={"sonar": (None, [[7, 7], [8, 8]])})
    assert data.scans[0].segments.tolist() == [[0, 0, 5, 5]]
    assert data.scans[1].points.tolist() == [[7, 7], [8, 8]]
    assert data.home() == (1, 2, 3)
    with pytest.raises(MapFormatError, match="shape"):
        from_stream(["2D-Map"], [[1, 2]], None)
    with pytest.raises(MapFormatError, match="Sources"):
        from_stream(["2D-Map"], None, None, scans={"Sonar": (None, None)})
    with pytest.raises(MapFormatError, match="not an ARIA map"):
        from_stream(["MinPos: 1 2"], None, None)
    # getMapBinary's header part may include the first tag line; it ends the header.
    assert from_stream(["2D-Map", "LINES", "junk"], None, [[1, 2]]).points.tolist() == [[1, 2]]


def test_named_scans_need_names_when_written() -> None:
    data = MapData(scans=[MapScan(), MapScan(name="Sonar")])
    with pytest.raises(ValueError, match="named scans"):
        map_bytes(data)


# -- property: anything we write reads back equal ------------------------------------------------------

_coord = st.integers(-(2**31), 2**31 - 1)
_name = st.text(st.characters(min_codepoint=32, max_codepoint=255, exclude_characters='"'), max_size=12)
# Latin-1 includes NBSP and NEL, which Python calls whitespace but ARIA (C isspace) does not.
_word = st.text(
    st.characters(min_codepoint=33, max_codepoint=255, exclude_characters='"'), min_size=1, max_size=10
)
_num = st.one_of(st.integers(-(10**9), 10**9), st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False))


@st.composite
def _objects(draw: st.DrawFn) -> MapObject:
    ends = draw(st.booleans())
    return MapObject(
        draw(_word),
        float(draw(_num)),
        float(draw(_num)),
        float(draw(_num)),
        draw(_name),
        draw(_word),
        draw(_name),
        (float(draw(_num)), float(draw(_num))) if ends else None,
        (float(draw(_num)), float(draw(_num))) if ends else None,
    )


@given(
    points=st.lists(st.tuples(_coord, _coord), max_size=30),
    segments=st.lists(st.tuples(_coord, _coord, _coord, _coord), max_size=10),
    objects=st.lists(_objects(), max_size=5),
    unknown=st.lists(_word.filter(lambda w: w.lower() not in ("data", "lines", "2d-map")), max_size=3),
    info=st.lists(st.tuples(st.sampled_from(["MapInfo", "MetaInfo", "_TaskInfo"]), _word), max_size=3),
    resolution=st.one_of(st.none(), st.integers(0, 1000)),
)
def test_written_maps_read_back_equal(
    points: list[tuple[int, int]],
    segments: list[tuple[int, int, int, int]],
    objects: list[MapObject],
    unknown: list[str],
    info: list[tuple[str, str]],
    resolution: int | None,
) -> None:
    unknown = [u for u in unknown if not u.lower().endswith(":") and not u[0].isdigit()]
    data = new_map(
        np.array(points, dtype=np.int64).reshape(-1, 2),
        np.array(segments, dtype=np.int64).reshape(-1, 4),
        objects=objects,
        resolution=resolution,
        info=[InfoLine(k, a) for k, a in info],
    )
    data.unknown_lines = [f"X{u}" for u in unknown]
    # Info lines come back grouped by keyword in writer order.
    order = ["MapInfo", "MetaInfo", "_TaskInfo"]
    data.info.sort(key=lambda line: order.index(line.keyword))
    again = parse_map(map_bytes(data))
    assert again == data
    assert again.skipped_lines == 0
    assert parse_map_lines(map_lines(data)) == data


@given(st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=12))
def test_any_name_is_written_exactly_or_refused(name: str) -> None:
    data = new_map(objects=[MapObject("Goal", 1, 2, name=name, description=name)])
    try:
        written = map_bytes(data)
    except ValueError:
        return
    assert parse_map(written).objects == data.objects


def test_repeated_sections_append_and_bytes_lines_work() -> None:
    lines = [b"2D-Map", b"DATA", b"1 2", b"LINES", b"0 0 1 1", b"DATA", b"3 4", b"lines", b"2 2 3 3"]
    data = parse_map_lines(lines)
    assert data.points.tolist() == [[1, 2], [3, 4]]
    assert data.segments.tolist() == [[0, 0, 1, 1], [2, 2, 3, 3]]


def test_big_sections_are_parsed_in_slices(monkeypatch: pytest.MonkeyPatch) -> None:
    from rtmu.mapfile import numeric

    rows = [f"{i} {-i}" for i in range(300)]
    rows[7] = "bad line"
    rows[250] = "9 9 9"
    text = "2D-Map\nDATA\n" + "\n".join(rows) + "\n"
    whole = parse_map(text)
    monkeypatch.setattr(numeric, "CHUNK_BYTES", 64)
    sliced = parse_map(text)
    assert sliced == whole and sliced.num_points == 298
    assert [w.line for w in sliced.warnings] == [w.line for w in whole.warnings] == [10, 253]
