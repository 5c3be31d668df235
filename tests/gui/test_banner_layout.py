"""Banners never cover the navigation pill (issue 21): at a phone's 360x720, at 800x480 and at 1280x800,
with two banners up while the robot navigates, the banner column and the pill do not overlap; on the
camera page (its own pill) neither."""

from __future__ import annotations

from collections.abc import Callable

from rtmu.base.notices import Kind, Notice
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

SIZES = ((360, 720), (800, 480), (1280, 800))
LONG = "The server says something long enough to wrap onto a second line of the banner, as servers do"


sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1)


def _bounds(gui: Gui, widget: object) -> tuple[float, float, float, float]:
    ok, rect = widget.compute_bounds(gui.window)  # type: ignore[attr-defined]
    assert ok
    return rect.get_x(), rect.get_y(), rect.get_width(), rect.get_height()


def _overlap(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


def _drawn_banners(gui: Gui) -> list[tuple[float, float, float, float]]:
    """The box of each banner shown (the column itself may be wider than what it draws)."""
    out = []
    child = gui.window.banners.get_first_child()
    while child is not None:
        box = child.get_child()  # type: ignore[attr-defined]
        if child.get_child_revealed() and box is not None:  # type: ignore[attr-defined]
            out.append(_bounds(gui, box))
        child = child.get_next_sibling()
    return out


def _covering(gui: Gui, pill: object) -> list[tuple[float, float, float, float]]:
    """The drawn banners that overlap ``pill`` now (and the pill's box last)."""
    box = _bounds(gui, pill)
    return [b for b in _drawn_banners(gui) if _overlap(b, box)]


def _settle(covering: Callable[[], list[tuple[float, float, float, float]]], where: str) -> None:
    """Wait until no banner covers the pill; fail saying which ones still do."""
    try:
        pump(lambda: not covering(), 5, "the banners to leave the pill")
    except AssertionError:
        raise AssertionError(f"{where} banners {covering()} cover the pill") from None


def test_banners_leave_the_navigation_pill_visible(gui: Gui) -> None:
    window = gui.window
    window.goals_panel.choose("Corridor End")
    pump(lambda: window.motion.kind == "autonomous", 10, "the navigation pill")
    session = gui.app.session
    assert session is not None
    for text in (LONG, "A second message from the server"):
        notice = Notice.warning(Kind.SERVER, text)
        session.runner.submit(lambda n=notice: session.runner._notice(n)).result(5)
    for width, height in SIZES:
        window.set_default_size(width, height)
        narrow = width < 600
        pump(lambda n=narrow: window.handheld.layout.narrow is n, 5, f"the layout at {width} px")
        idle(0.5)
        pump(lambda: len(_drawn_banners(gui)) >= 2, 5, "two banners")
        idle(0.4)  # the reveal's slide and the relayout
        for text in (LONG, "A second message from the server"):  # keep them up (4 s timeout)
            window.banners.tell(f"notice:{text}", "warning", text, timeout=None)
        assert window.motion.get_mapped(), f"the pill is hidden at {width}x{height}"
        # Waited for, not slept on: on a busy machine the relayout after a resize can take a while.
        _settle(lambda: _covering(gui, window.motion), f"at {width}x{height}")
        gui.shot(f"{width}x{height}")
    # The camera page's pill, on a phone: the banners start under it too.
    window.set_default_size(360, 720)
    pump(lambda: window.handheld.layout.narrow, 5, "the phone layout")
    gui.key("Escape")
    pill = window.camera_page.motion
    pump(lambda: pill.get_mapped() and pill.kind == "autonomous", 5, "the camera page's pill")
    for text in (LONG, "A second message from the server"):
        window.banners.tell(f"notice:{text}", "warning", text, timeout=None)
    _settle(lambda: _covering(gui, pill), "on the camera page at 360x720")
    gui.shot("camera-page-360x720")
    # The bar's word buttons are icons on a phone (their words were cut to a letter), words in the tip.
    view = window.camera
    pump(lambda: view.compact, 3, "the compact camera bar")
    assert view.back_button.get_icon_name() == "go-previous-symbolic"
    assert view.back_button.get_tooltip_text() == "Back to map (Esc)"
    window.set_default_size(1280, 800)
    pump(lambda: not view.compact, 5, "the words back on a wide window")
    assert view.back_button.get_label() == "Back to map (Esc)"
    gui.key("space")
    pump(lambda: window.motion.kind == "", 5, "Space to end the navigation")
