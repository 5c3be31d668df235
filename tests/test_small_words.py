"""Small words the window says, right (issue 21, "Smaller"): headings, the palette's count, About."""

from __future__ import annotations

from pathlib import Path

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


def test_saved_frames_go_to_the_pictures_folder_the_readme_names(tmp_path: Path) -> None:
    """``~/Pictures/rtmu`` where the desktop set no pictures folder; its own folder where it did."""
    import subprocess
    import sys

    probe = "from rtmu.ui.live_video import frames_dir; print(frames_dir())"
    home = tmp_path / "home"
    (home / ".config").mkdir(parents=True)
    env = {"HOME": str(home), "XDG_CONFIG_HOME": str(home / ".config"), "PATH": "/usr/bin:/bin"}
    env["PYTHONPATH"] = ":".join(sys.path)
    said = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True)
    assert said.stdout.strip() == str(home / "Pictures" / "rtmu")
    (home / ".config" / "user-dirs.dirs").write_text('XDG_PICTURES_DIR="$HOME/Bilder"\n', encoding="utf-8")
    said = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True)
    assert said.stdout.strip() == str(home / "Bilder" / "rtmu")
