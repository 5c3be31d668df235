"""``rtmu --install-desktop`` / ``--man`` / ``--completion``: the desktop entry, man page and completions.

They are generated from the parser the command uses, installed only on request into the user's XDG data
folder, valid to the tools that read them (desktop-file-validate, appstreamcli, bash), and removed again.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.cli import build_parser
from rtmu.package_data import APP_ID
from rtmu.subcommands._integration import completion, desktop_entry, exec_line, man_page

ROOT = Path(__file__).resolve().parents[1]


def rtmu(*args: str, data_home: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    if data_home is not None:
        env["XDG_DATA_HOME"] = str(data_home)
    return subprocess.run(
        [sys.executable, "-m", "rtmu", *args], capture_output=True, text=True, timeout=120, env=env
    )


def subcommand_names() -> list[str]:
    parser = build_parser()
    (sub,) = [a for a in parser._actions if a.dest == "subcommand"]
    return sorted(sub.choices)  # type: ignore[arg-type]


def test_install_puts_valid_files_where_desktops_man_and_shells_look_and_uninstall_removes_them(
    tmp_path: Path,
) -> None:
    share = tmp_path / "root" / "usr" / "share"  # laid out like /usr/share, for appstreamcli validate-tree
    done = rtmu("--install-desktop", data_home=share)
    assert done.returncode == 0, done.stderr
    wanted = [
        f"applications/{APP_ID}.desktop",
        f"icons/hicolor/scalable/apps/{APP_ID}.svg",
        f"metainfo/{APP_ID}.metainfo.xml",
        "man/man1/rtmu.1",
        "bash-completion/completions/rtmu",
        "zsh/site-functions/_rtmu",
        "fish/vendor_completions.d/rtmu.fish",
    ]
    for relative in wanted:
        assert (share / relative).is_file(), relative
        assert f"installed   {share / relative}" in done.stdout
    entry = (share / f"applications/{APP_ID}.desktop").read_text()
    assert f'Exec="{sys.executable}" "-m" "rtmu"\n' in entry  # this very RTMU, not whatever is on PATH
    assert f'Exec="{sys.executable}" "-m" "rtmu" --demo\n' in entry
    check = subprocess.run(
        ["desktop-file-validate", str(share / f"applications/{APP_ID}.desktop")],
        capture_output=True,
        text=True,
    )
    assert check.returncode == 0 and not check.stdout.strip(), check.stdout
    tree = subprocess.run(
        ["appstreamcli", "validate-tree", "--no-net", str(tmp_path / "root")], capture_output=True, text=True
    )
    assert tree.returncode == 0, tree.stdout + tree.stderr

    again = rtmu("--install-desktop", data_home=share)
    assert again.returncode == 0 and again.stdout.count("up to date") == len(wanted), again.stdout

    gone = rtmu("--uninstall-desktop", data_home=share)
    assert gone.returncode == 0, gone.stderr
    assert [p for p in share.rglob("*") if p.is_file()] == []
    assert "nothing of RTMU's was installed" in rtmu("--uninstall-desktop", data_home=share).stdout


def test_a_data_folder_that_cannot_be_written_is_a_clear_error_and_leaves_nothing(tmp_path: Path) -> None:
    blocker = tmp_path / "share"
    blocker.write_text("a file where the data folder should be\n")
    done = rtmu("--install-desktop", data_home=blocker)
    assert done.returncode == 1
    assert f"rtmu: cannot install into {blocker}" in done.stderr and "Traceback" not in done.stderr
    assert blocker.read_text() == "a file where the data folder should be\n"


def test_exec_quotes_paths_with_spaces_and_shell_characters_as_the_desktop_spec_asks(tmp_path: Path) -> None:
    command = ['/opt/my robots/$HOME/"rtmu"', "-m", "rtmu"]
    assert exec_line(command) == '"/opt/my robots/\\$HOME/\\"rtmu\\"" "-m" "rtmu"'
    path = tmp_path / f"{APP_ID}.desktop"
    path.write_bytes(desktop_entry(command))
    check = subprocess.run(["desktop-file-validate", str(path)], capture_output=True, text=True)
    assert check.returncode == 0 and not check.stdout.strip(), check.stdout


def test_the_man_page_documents_every_subcommand_and_the_exit_codes() -> None:
    page = man_page(build_parser())
    assert page.startswith('.TH RTMU "1"') and "rtmu \\- drive and commission" in page
    for name in subcommand_names():
        assert f"'rtmu {name}'" in page, name
    assert ".SH EXIT STATUS" in page and "13 login" in page
    done = rtmu("--man")
    assert done.returncode == 0 and done.stdout.startswith('.TH RTMU "1"')


def test_bash_completes_subcommands_and_their_options_from_the_generated_script(tmp_path: Path) -> None:
    script = tmp_path / "rtmu.bash"
    script.write_text(rtmu("--completion", "bash").stdout)
    probe = (
        f"source {script}\n"
        'complete_words() { COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); COMPREPLY=(); _shtab_rtmu; '
        'printf "%s\\n" "${COMPREPLY[@]}"; }\n'
        "echo '--'; complete_words rtmu si\n"
        "echo '--'; complete_words rtmu sim --ma\n"
        "echo '--'; complete_words rtmu --inst\n"
    )
    done = subprocess.run(["bash", "-c", probe], capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    _, first, second, third = done.stdout.split("--\n")
    assert first.split() == ["sim"]
    assert "--map" in second.split()
    assert third.split() == ["--install-desktop"]


@pytest.mark.parametrize(("shell", "marker"), [("zsh", "#compdef rtmu"), ("fish", "complete -c rtmu")])
def test_zsh_and_fish_scripts_name_every_subcommand(shell: str, marker: str) -> None:
    text = completion(build_parser(), shell)
    assert marker in text
    for name in subcommand_names():
        assert name in text, (shell, name)


def test_an_unknown_shell_is_a_usage_error() -> None:
    done = rtmu("--completion", "powershell")
    assert done.returncode == 2 and "invalid choice" in done.stderr
