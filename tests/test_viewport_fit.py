"""Fit in what an overlay leaves (``viewport.fit_view`` insets, ``best_fit``): the D-pad's room."""

from __future__ import annotations

from rtmu.ui.viewport import best_fit, fit_view

OFFICE = (0.0, 0.0, 30000.0, 12000.0)


def test_a_left_inset_puts_the_whole_map_right_of_it() -> None:
    view = fit_view(OFFICE, 790, 390, insets=(228, 0, 0, 0))
    left, _ = view.to_screen(0.0, 6000.0)
    right, _ = view.to_screen(30000.0, 6000.0)
    assert left >= 228 and right <= 790, (left, right)
    assert view.zoom < fit_view(OFFICE, 790, 390).zoom


def test_a_bottom_inset_puts_the_whole_map_above_it() -> None:
    view = fit_view(OFFICE, 360, 560, insets=(0, 0, 0, 280))
    _, top = view.to_screen(15000.0, 12000.0)
    _, bottom = view.to_screen(15000.0, 0.0)
    assert top >= 0 and bottom <= 560 - 280, (top, bottom)


def test_best_fit_takes_the_choice_that_shows_the_map_largest() -> None:
    beside, above = (228, 0, 0, 0), (0, 0, 0, 224)
    view = best_fit(OFFICE, 790, 390, (beside, above))
    assert view == fit_view(OFFICE, 790, 390, insets=beside)  # a wide map beside a corner pad
    assert best_fit(OFFICE, 790, 390, ()) == fit_view(OFFICE, 790, 390)


def test_no_room_worth_taking_leaves_the_plain_fit() -> None:
    """A split phone's small map under a big D-pad: the plain fit, not a map a few pixels high."""
    assert best_fit(OFFICE, 350, 322, ((0, 0, 0, 276),)) == fit_view(OFFICE, 350, 322)


def test_the_plain_fit_still_keeps_clear_of_the_floor() -> None:
    """When the D-pad's room would shrink the map too far, the plain fit still leaves the zoom row
    (``floor``) its room: left of it or above it, whichever shows the map larger."""
    zoom_row = ((0, 0, 247, 0), (0, 0, 0, 68))
    tight = ((236, 0, 0, 68), (0, 0, 0, 340))
    view = best_fit(OFFICE, 395, 390, tight, zoom_row)
    assert view == fit_view(OFFICE, 395, 390, insets=(0, 0, 0, 68))
    assert view != fit_view(OFFICE, 395, 390)  # same zoom here, moved up off the row
