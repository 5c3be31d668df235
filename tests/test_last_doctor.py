"""``rtmu doctor``'s last report, kept for About: written whole, read bounded, a missing one said."""

from __future__ import annotations

from pathlib import Path

from rtmu.settings.last_doctor import MAX_BYTES, last_doctor_path, load_last_doctor, save_last_doctor


def test_the_last_report_is_kept_and_replaced(tmp_path: Path) -> None:
    env = {"XDG_DATA_HOME": str(tmp_path)}
    assert "has not been run" in load_last_doctor(env)
    save_last_doctor(["rtmu doctor a:1", "first"], env)
    save_last_doctor(["rtmu doctor b:2", "All steps passed"], env)
    text = load_last_doctor(env)
    assert "b:2" in text and "All steps passed" in text and "first" not in text
    assert last_doctor_path(env) == tmp_path / "rtmu" / "last-doctor.txt"


def test_a_home_that_cannot_be_written_loses_only_the_report(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    save_last_doctor(["x"], {"XDG_DATA_HOME": str(blocker)})  # no exception
    assert "has not been run" in load_last_doctor({"XDG_DATA_HOME": str(blocker)})


def test_a_huge_file_is_read_only_in_part(tmp_path: Path) -> None:
    env = {"XDG_DATA_HOME": str(tmp_path)}
    path = last_doctor_path(env)
    path.parent.mkdir(parents=True)
    path.write_bytes(b"\xff" + b"a" * (MAX_BYTES * 4))
    assert len(load_last_doctor(env)) <= MAX_BYTES
