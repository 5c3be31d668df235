"""Putting RTMU into the desktop and the shell, only when the operator asks: ``rtmu --install-desktop``.

Nothing is installed as a side effect of running or setting up RTMU. ``--install-desktop`` copies the
desktop entry (its ``Exec`` pointing at this very ``rtmu``), the icon and the AppStream metainfo, and
writes the man page and the bash, zsh and fish completions, all into the user's XDG data folder
(``~/.local/share``), where desktops, ``man`` and the shells look; ``--uninstall-desktop`` removes
them again. ``--man`` and ``--completion SHELL`` print the page or a script instead, for packagers and
for people who keep them elsewhere. Page and scripts are generated from the parser the command itself
uses (argparse-manpage, shtab), so they cannot drift from it.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

from .. import __version__
from ..base.i18n import _
from ..base.xdg import DATA, xdg_home
from ..package_data import APP_ID, DESKTOP_DIR

EXIT_CANNOT_WRITE = 1
SHELLS = ("bash", "zsh", "fish")

MAN_SECTIONS = (
    (
        "exit status",
        "0 done; 2 bad usage (or an unknown name); 3 no connection, a refused login or a protocol fault; "
        "4 the server does not offer it; 5 timed out. Navigation commands add 6 could not get there, 7 "
        "stopped before arriving, 8 the robot is lost; rtmu config --set 6 refused; rtmu doctor exits with "
        "the failing step: 10 name resolution, 11 TCP connect, 12 introduction, 13 login, 14 data list, "
        "15 first status.",
    ),
    (
        "files",
        "~/.config/rtmu/settings.toml: connection profiles and view choices (passwords live in the desktop "
        "keyring, never here). ~/.local/share/rtmu/recordings/: the flight recorder's MCAP files.",
    ),
    (
        "see also",
        "The operator's guide, safety notes and troubleshooting in RTMU's documentation (docs/ in its "
        "source). RTMU's STOP is an operational stop: it is no substitute for the robot's emergency stop.",
    ),
)


class Installed(NamedTuple):
    """One file ``--install-desktop`` writes: where (under the data folder) and what."""

    relative: str
    content: bytes


def add_arguments(parser: argparse.ArgumentParser) -> None:
    g = parser.add_argument_group("installation (for this user; nothing is installed unless asked)")
    g.add_argument(
        "--install-desktop",
        action="store_true",
        help=_(
            "put RTMU in the desktop's application menu and install its man page and shell completions "
            "(under $XDG_DATA_HOME, ~/.local/share)"
        ),
    )
    g.add_argument(
        "--uninstall-desktop", action="store_true", help=_("remove what --install-desktop installed")
    )
    g.add_argument("--man", action="store_true", help=_("print the man page (roff) and exit"))
    g.add_argument(
        "--completion", choices=SHELLS, metavar="SHELL", help=_("print a completion script for SHELL")
    )


def handle(args: argparse.Namespace, full_parser: Callable[[], argparse.ArgumentParser]) -> int | None:
    """Do what one of these options asks and return the exit code; None when none was given.

    ``full_parser`` builds the parser with every subcommand (what the page and the completions
    describe), only when one of these options asks for it."""
    if not any(getattr(args, o, None) for o in ("man", "completion", "install_desktop", "uninstall_desktop")):
        return None
    parser = full_parser()
    if getattr(args, "man", False):
        sys.stdout.write(man_page(parser))
        return 0
    shell = getattr(args, "completion", None)
    if shell is not None:
        sys.stdout.write(completion(parser, shell))
        return 0
    if getattr(args, "install_desktop", False):
        return install(parser, xdg_home(DATA), rtmu_command())
    if getattr(args, "uninstall_desktop", False):
        return uninstall(parser, xdg_home(DATA))
    return None


def rtmu_command() -> list[str]:
    """How the desktop should start this RTMU: its ``rtmu`` script, or this Python with ``-m rtmu``."""
    script = Path(sys.argv[0]) if sys.argv and sys.argv[0] else None
    if script is not None and script.name == "rtmu" and script.is_file():
        return [str(script.absolute())]  # not resolved: pipx's ~/.local/bin/rtmu link survives upgrades
    return [sys.executable, "-m", "rtmu"]


def exec_line(command: list[str]) -> str:
    """The Desktop Entry ``Exec`` words: each argument quoted, with ``" ` $ \\`` escaped inside."""
    quoted = []
    for word in command:
        escaped = "".join("\\" + c if c in '"`$\\' else c for c in word)
        quoted.append(f'"{escaped}"')
    return " ".join(quoted)


def desktop_entry(command: list[str]) -> bytes:
    """The shipped entry with every ``Exec=rtmu…`` line starting ``command`` instead."""
    text = (DESKTOP_DIR / f"{APP_ID}.desktop").read_text(encoding="utf-8")
    lines = [
        "Exec=" + exec_line(command) + line[len("Exec=rtmu") :] if line.startswith("Exec=rtmu") else line
        for line in text.splitlines()
    ]
    return ("\n".join(lines) + "\n").encode()


def man_page(parser: argparse.ArgumentParser) -> str:
    from argparse_manpage.manpage import Manpage

    page = Manpage(parser)
    page.description = "drive and commission ArNetworking (ARIA) mobile robots"
    page.source = f"rtmu {__version__}"
    page.manual = "RTMU manual"
    for heading, text in MAN_SECTIONS:
        page.add_section(heading, "=", text.replace("\\", "\\e").replace("-", "\\-"))  # roff escapes
    return str(page)


def completion(parser: argparse.ArgumentParser, shell: str) -> str:
    import shtab

    return str(shtab.complete(parser, shell=shell))


def files(parser: argparse.ArgumentParser, command: list[str]) -> list[Installed]:
    return [
        Installed(f"applications/{APP_ID}.desktop", desktop_entry(command)),
        Installed(f"icons/hicolor/scalable/apps/{APP_ID}.svg", (DESKTOP_DIR / f"{APP_ID}.svg").read_bytes()),
        Installed(f"metainfo/{APP_ID}.metainfo.xml", (DESKTOP_DIR / f"{APP_ID}.metainfo.xml").read_bytes()),
        Installed("man/man1/rtmu.1", man_page(parser).encode()),
        Installed("bash-completion/completions/rtmu", completion(parser, "bash").encode()),
        Installed("zsh/site-functions/_rtmu", completion(parser, "zsh").encode()),
        Installed("fish/vendor_completions.d/rtmu.fish", completion(parser, "fish").encode()),
    ]


def install(parser: argparse.ArgumentParser, home: Path, command: list[str]) -> int:
    """Write each file that is missing or differs (a re-run changes nothing); say what was done."""
    try:
        for item in files(parser, command):
            target = home / item.relative
            if target.is_file() and target.read_bytes() == item.content:
                print(_("up to date  {target}").format(target=target))
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = target.with_name(target.name + ".rtmu-new")
            partial.write_bytes(item.content)
            partial.chmod(0o644)
            partial.replace(target)  # atomic: a reader never sees half a file
            print(_("installed   {target}").format(target=target))
    except BrokenPipeError:
        raise  # our reader went away: not a reason to blame the data folder
    except OSError as exc:
        print(_("rtmu: cannot install into {home}: {exc}").format(home=home, exc=exc), file=sys.stderr)
        return EXIT_CANNOT_WRITE
    print(
        _("RTMU is in the application menu; zsh users add {value} to fpath.").format(
            value=home / "zsh/site-functions"
        )
    )
    return 0


def uninstall(parser: argparse.ArgumentParser, home: Path) -> int:
    """Remove every file ``install`` writes (by name: they are named after RTMU); say what went."""
    removed = 0
    for item in files(parser, []):
        target = home / item.relative
        try:
            target.unlink()
        except FileNotFoundError:
            continue
        except OSError as exc:
            print(_("rtmu: cannot remove {target}: {exc}").format(target=target, exc=exc), file=sys.stderr)
            return EXIT_CANNOT_WRITE
        removed += 1
        print(_("removed     {target}").format(target=target))
    if not removed:
        print(_("nothing of RTMU's was installed in {home}").format(home=home))
    return 0
