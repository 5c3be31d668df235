"""A stop's explanation is a notice marked as one, and the window also writes it on stderr, once."""

from __future__ import annotations

import pytest

from rtmu.base.notices import Kind, Level, Notice
from rtmu.ui.notice_router import say_stop


def test_a_stop_notice_is_marked_and_keeps_its_level() -> None:
    link = Notice.stopped(Kind.LINK, "Stopped: the link is stale — no status for 0.46 s")
    assert link.stop and link.level is Level.WARNING
    guardian = Notice.stopped(Kind.SAFETY, "The guardian stopped the robot", Level.ERROR)
    assert guardian.stop and guardian.level is Level.ERROR, "the recorder reads a guardian stop by its level"
    assert not Notice.warning(Kind.LINK, "The link is stale").stop


def test_a_stop_is_written_on_stderr_once_and_nothing_else_is(capsys: pytest.CaptureFixture[str]) -> None:
    say_stop(Notice.stopped(Kind.LINK, "Stopped: the link is stale"))
    say_stop(Notice.stopped(Kind.SAFETY, "Stopped 2: 3 is selected now.", Level.INFO), robot="robot 2")
    say_stop(Notice.warning(Kind.LINK, "The link is slow"))
    say_stop(Notice.info(Kind.SPEED, "Speed 50 %"))
    assert capsys.readouterr().err.splitlines() == [
        "rtmu: Stopped: the link is stale",
        "rtmu: robot 2: Stopped 2: 3 is selected now.",
    ]
