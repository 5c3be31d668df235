"""base.xdg: one rule for every folder RTMU keeps files in (the XDG base directory specification)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rtmu.base.dataclass_code import cache_file
from rtmu.base.xdg import CACHE, CONFIG, DATA, xdg_home
from rtmu.recorder.files import recordings_dir
from rtmu.settings.last_doctor import last_doctor_path
from rtmu.settings.store import config_dir

FOLDERS = [(CONFIG, ".config"), (DATA, ".local/share"), (CACHE, ".cache")]


@pytest.mark.parametrize(("which", "default"), FOLDERS)
def test_an_absolute_value_is_used_and_anything_else_means_the_default(
    which: tuple[str, str], default: str, tmp_path: Path
) -> None:
    variable = which[0]
    assert xdg_home(which, {variable: str(tmp_path)}) == tmp_path
    for ignored in ({}, {variable: ""}, {variable: "relative/folder"}):
        assert xdg_home(which, ignored) == Path.home() / default


def test_every_file_rtmu_keeps_follows_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    env = {"XDG_CONFIG_HOME": str(tmp_path / "c"), "XDG_DATA_HOME": str(tmp_path / "d")}
    assert config_dir(env) == tmp_path / "c" / "rtmu"
    assert recordings_dir(env) == tmp_path / "d" / "rtmu" / "recordings"
    assert last_doctor_path(env) == tmp_path / "d" / "rtmu" / "last-doctor.txt"
    monkeypatch.setenv("XDG_CACHE_HOME", "not/absolute")
    assert cache_file().parent == Path.home() / ".cache" / "rtmu"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "k"))
    assert cache_file().parent == tmp_path / "k" / "rtmu"
