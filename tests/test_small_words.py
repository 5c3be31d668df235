"""Small words the window says, right (issue 21, "Smaller"): headings, the palette's count, About."""

from __future__ import annotations

from rtmu.ui.notes import heading_text


def test_a_heading_is_never_minus_zero() -> None:
    assert heading_text(-0.3) == "0°"
    assert heading_text(-0.0) == "0°"
    assert heading_text(-0.6) == "-1°"
    assert heading_text(89.6) == "90°"
    assert heading_text(-180.0) == "-180°"


def test_the_palette_counts_what_its_filter_shows() -> None:
    from rtmu.ui.palette import count_note

    assert count_note(12, 12, 0, "") == "12 commands"
    assert count_note(1, 12, 0, "trip odo") == "1 of 12 commands"
    assert count_note(0, 12, 0, " xyz ") == "No command matches “xyz” (12 in all)"
    assert count_note(0, 0, 3, "") == "The server offers this user no commands."
    assert count_note(1, 1, 2, "") == "1 command (2 more the server has are not open to this user)"


def test_about_says_its_licence_once_and_has_its_own_logo() -> None:
    from rtmu.ui.about import LICENSE_TEXT, app_logo

    assert "MIT License" in LICENSE_TEXT and "The The" not in LICENSE_TEXT and "the The" not in LICENSE_TEXT
    logo = app_logo()
    assert logo is not None and logo.get_width() > 0, "the package's own icon could not be read"
