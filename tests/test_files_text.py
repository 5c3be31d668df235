"""The files page's words: sizes, dates, transfers and why a feature is greyed (no window needed)."""

from __future__ import annotations

from rtmu.ui.files_text import greyed, human_size, parent_of, remote_join, transfer_text, when
from rtmu.values.commission import Direction, Transfer


def test_sizes_in_decimal_units() -> None:
    assert [human_size(n) for n in (0, 999, 1000, 1_234_567, 52_428_800, 5 * 10**12)] == [
        "0 B", "999 B", "1.0 kB", "1.2 MB", "52.4 MB", "5000 GB",
    ]  # fmt: skip


def test_dates_and_paths() -> None:
    assert when(0) == "" and when(2**62) == "" and len(when(1_700_000_000)) == 16
    assert remote_join("", "a") == "a" and remote_join("maps", "a.map") == "maps/a.map"
    assert parent_of("maps/old") == "maps" and parent_of("maps") == ""


def test_each_feature_greyed_with_its_own_reason() -> None:
    assert set(greyed((), False).values()) == {"not connected to a robot"}
    assert greyed({"getDirListing", "getFile", "putFile", "deleteFile"}, True) == {}
    only_listing = greyed({"getDirListingMultiplePackets"}, True)
    assert set(only_listing) == {"download", "upload", "delete"}
    assert "offers no putFile" in only_listing["upload"] and "may not use it" in only_listing["upload"]


def test_a_transfer_in_words() -> None:
    t = Transfer(Direction.UPLOAD, "maps/new.map", "/tmp/new.map", 1_500_000, 3_000_000)
    assert transfer_text(t) == "Uploading maps/new.map — 1.5 MB of 3.0 MB" and t.fraction == 0.5
    assert transfer_text(Transfer(Direction.DOWNLOAD, "x", "y", 10)) == "Downloading x — 10 B"
