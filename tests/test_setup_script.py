"""The set-up from nothing: the README's two commands need only bash, and scripts/setup.sh picks and
installs a Python >= 3.11 and the system packages on Debian 12 and Ubuntu 22.04.

The apt side runs against stand-ins for ``dpkg-query``, ``apt-cache``, ``apt-get`` and the Python
interpreters on a PATH of their own (a test cannot install packages); they record what the script
asked for, so each scenario checks the exact apt commands and the interpreter chosen.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
OTHER_PACKAGES = [
    "gir1.2-gtk-4.0",
    "gir1.2-adw-1",
    "gir1.2-manette-0.2",
    "libgirepository1.0-dev",
    "libcairo2-dev",
    "pkg-config",
    "build-essential",
    "xvfb",
    "xdotool",
    "openbox",
    "x11-utils",
    "xxd",
    "bsdextrautils",
    "appstream",
    "desktop-file-utils",
    "dbus",
    "git",
    "at-spi2-core",
    "python3-pyatspi",
]
TOOLS = [
    "awk",
    "grep",
    "cat",
    "mktemp",
    "tail",
    "rm",
    "sha256sum",
    "cut",
    "tr",
    "ls",
    "dirname",
    "env",
    "bash",
    "printf",
    "sed",
    "touch",
    "chmod",
]
DEBIAN_12 = {
    "python3": "3.11.2-1+b1",
    "python3.11": "3.11.2-6+deb12u6",
    "python3.11-venv": "3.11.2-6+deb12u6",
    "dbus-daemon": "1.14.10-1~deb12u1",  # split out of dbus on Debian 12 (setup.sh's SPLIT_PACKAGES)
}
UBUNTU_22_04 = {
    "python3": "3.10.6-1~22.04",
    "python3.11": "3.11.0~rc1-1~22.04",
    "python3.11-venv": "3.11.0~rc1-1",
}


def _script(path: Path, text: str) -> None:
    path.write_text("#!/bin/bash\n" + text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)


def _fake_python(bin_dir: Path, name: str, version: str) -> None:
    minor = int(version.split(".")[1])
    _script(
        bin_dir / name,
        f'case "$*" in *"version_info < (3, 11)"*) exit {0 if minor >= 11 else 1};; esac\n'
        f'[ "$1" = -V ] && echo "Python {version}"\nexit 0\n',
    )


@dataclass
class Machine:
    """A pretend Debian/Ubuntu: installed packages, apt's candidates, interpreters on PATH, a uid."""

    root: Path
    candidates: dict[str, str]

    @property
    def bin(self) -> Path:
        return self.root / "bin"

    def installed(self) -> list[str]:
        return (self.root / "installed").read_text().split()

    def apt_calls(self) -> list[str]:
        log = self.root / "apt.log"
        return log.read_text().splitlines() if log.exists() else []

    def run(self, *, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
        """Source setup.sh (runs nothing) and do its system-package step twice (the re-run is a no-op)."""
        command = (
            "source scripts/setup.sh; ensure_system_packages; "
            'echo "PYTHON=$PYTHON"; ensure_system_packages; echo "PYTHON=$PYTHON"'
        )
        return subprocess.run(
            ["bash", "-c", command],
            cwd=ROOT,
            env={"PATH": f"{self.bin}:{self.root / 'tools'}", **(env or {})},
            capture_output=True,
            text=True,
            timeout=30,
        )


def make_machine(
    tmp_path: Path,
    *,
    installed: list[str],
    pythons: dict[str, str],
    candidates: dict[str, str],
    uid: int = 0,
    lists: bool = False,
) -> Machine:
    root = tmp_path / "machine"
    (root / "bin").mkdir(parents=True)
    (root / "tools").mkdir()
    for tool in TOOLS:
        real = shutil.which(tool)
        assert real, tool
        (root / "tools" / tool).symlink_to(real)
    (root / "installed").write_text("\n".join(installed) + "\n")
    if lists:
        (root / "lists").touch()
    for name, version in pythons.items():
        _fake_python(root / "bin", name, version)
    _script(root / "bin" / "id", f"echo {uid}\n")
    _script(
        root / "bin" / "dpkg-query",
        f'shift 2\nfor p in "$@"; do grep -qxF "$p" {root}/installed && echo "$p installed"; done\nexit 0\n',
    )
    table = "\n".join(f"{name}) c={version};;" for name, version in candidates.items())
    _script(
        root / "bin" / "apt-cache",
        f'c="(none)"\nif [ -e {root}/lists ]; then case "$2" in\n{table}\nesac; fi\n'
        'printf "%s:\\n  Installed: (none)\\n  Candidate: %s\\n" "$2" "$c"\n',
    )
    # apt-get install also puts the interpreters it installs on PATH, as the real packages would.
    _script(
        root / "mkpy",
        f"cat > {root}/bin/$1 <<EOF\n#!/bin/bash\n"
        'case "\\$*" in *"version_info < (3, 11)"*) [ $2 -ge 11 ]; exit;; esac\n'
        '[ "\\$1" = -V ] && echo "Python 3.$2"\nexit 0\nEOF\n'
        f"chmod +x {root}/bin/$1\n",
    )
    pythons_installed = "\n".join(
        f"{name}) {root}/mkpy {name} {int(version.split('.')[1].split('~')[0].split('-')[0])};;"
        for name, version in candidates.items()
        if re.fullmatch(r"python3(\.\d+)?", name)
    )
    _script(
        root / "bin" / "apt-get",
        f'echo "apt-get $*" >> {root}/apt.log\n'
        f'case "$1" in\n  update) touch {root}/lists;;\n  install)\n'
        f'    for p in "$@"; do case "$p" in -*|install|Dpkg*) continue;; esac\n'
        f'      echo "$p" >> {root}/installed\n'
        f'      case "$p" in\n{pythons_installed}\n      esac\n    done;;\nesac\n',
    )
    return Machine(root, candidates)


def _install_calls(machine: Machine) -> list[list[str]]:
    return [call.split()[1:] for call in machine.apt_calls() if call.startswith("apt-get install")]


def _packages(call: list[str]) -> list[str]:
    return [word for word in call if not word.startswith("-") and word != "install" and "Dpkg" not in word]


def test_bare_debian_12_gets_python3_and_everything_else(tmp_path: Path) -> None:
    machine = make_machine(tmp_path, installed=[], pythons={}, candidates=DEBIAN_12)
    result = machine.run()
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("PYTHON=python3\n") == 2
    assert machine.apt_calls()[0] == "apt-get update -q"
    (install,) = _install_calls(machine)
    assert _packages(install) == ["python3", "python3-venv", "python3-dev", *OTHER_PACKAGES, "dbus-daemon"]


def test_bare_ubuntu_22_04_gets_python3_11_because_its_python3_is_3_10(tmp_path: Path) -> None:
    machine = make_machine(tmp_path, installed=[], pythons={}, candidates=UBUNTU_22_04)
    result = machine.run()
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("PYTHON=python3.11\n") == 2
    (install,) = _install_calls(machine)
    assert _packages(install) == ["python3.11", "python3.11-venv", "python3.11-dev", *OTHER_PACKAGES]
    assert "dbus-daemon" not in result.stdout  # Ubuntu 22.04's dbus holds the daemon: no such package


def test_ubuntu_22_04_with_its_python3_adds_only_python3_11(tmp_path: Path) -> None:
    machine = make_machine(
        tmp_path,
        installed=["python3", *OTHER_PACKAGES],
        pythons={"python3": "3.10.12"},
        candidates=UBUNTU_22_04,
        lists=True,
    )
    result = machine.run()
    assert result.returncode == 0, result.stderr
    assert "using python3.11" in result.stdout
    (install,) = _install_calls(machine)
    assert _packages(install) == ["python3.11", "python3.11-venv", "python3.11-dev"]


def test_a_ready_machine_asks_apt_nothing(tmp_path: Path) -> None:
    machine = make_machine(
        tmp_path,
        installed=["python3", "python3-venv", "python3-dev", *OTHER_PACKAGES, "dbus-daemon"],
        pythons={"python3": "3.11.2"},
        candidates=DEBIAN_12,
    )
    result = machine.run()
    assert result.returncode == 0, result.stderr
    assert f"system packages present ({3 + len(OTHER_PACKAGES) + 1} checked)" in result.stdout
    assert machine.apt_calls() == []


def test_missing_venv_module_is_installed(tmp_path: Path) -> None:
    machine = make_machine(
        tmp_path,
        installed=["python3", *OTHER_PACKAGES, "dbus-daemon"],  # Debian 12's dbus depends on it
        pythons={"python3": "3.11.2"},
        candidates=DEBIAN_12,
    )
    assert machine.run().returncode == 0
    (install,) = _install_calls(machine)
    assert _packages(install) == ["python3-venv", "python3-dev"]


def test_without_root_or_sudo_it_prints_the_commands_and_stops(tmp_path: Path) -> None:
    machine = make_machine(tmp_path, installed=[], pythons={}, candidates=DEBIAN_12, uid=1000)
    result = machine.run()
    assert result.returncode == 1
    assert "sudo apt-get install -y python3 python3-venv python3-dev" in result.stderr
    assert "sudo apt-get install -y python3.11 python3.11-venv python3.11-dev" in result.stderr
    assert machine.apt_calls() == []


def test_no_python_anywhere_is_a_clear_error(tmp_path: Path) -> None:
    machine = make_machine(tmp_path, installed=[], pythons={}, candidates={"python3": "3.9.2-3"})
    result = machine.run()
    assert result.returncode == 1
    assert "no Python >= 3.11" in result.stderr


# -- the commands the README gives -----------------------------------------------------------


def _readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = re.search(r"## Set-up: two commands.*?```sh\n(.*?)```", text, re.S)
    assert block, "README: no set-up block"
    return [line.split("#")[0].strip() for line in block.group(1).splitlines() if line.strip()]


def test_readme_starts_with_two_commands_that_need_only_bash() -> None:
    demo, test = _readme_commands()
    assert (demo, test) == ("./rtmu-dev demo", "./rtmu-dev test")
    script = ROOT / "rtmu-dev"
    assert script.read_text().startswith("#!/usr/bin/env bash\n")
    assert os.access(script, os.X_OK)


def test_ci_runs_the_readme_test_command_verbatim() -> None:
    test = _readme_commands()[1]
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.search(rf"^(exec )?{re.escape(test)}\b", ci, re.M)
    assert "make" not in ci.replace("makes", "")


@pytest.mark.parametrize("target", ["setup", "demo", "test", "lint", "format", "bench"])
def test_make_targets_are_aliases(target: str) -> None:
    makefile = (ROOT / "Makefile").read_text()
    assert re.search(rf"^[\w ]*\b{target}\b[\w ]*:\n\t@bash rtmu-dev \$@$", makefile, re.M)


def test_rtmu_dev_help_runs_without_the_set_up() -> None:
    result = subprocess.run(
        ["bash", str(ROOT / "rtmu-dev"), "help"], capture_output=True, text=True, timeout=30, check=False
    )
    assert result.returncode == 0
    assert "demo" in result.stdout and "test" in result.stdout
    bad = subprocess.run(
        ["bash", str(ROOT / "rtmu-dev"), "nonsense"], capture_output=True, text=True, timeout=30
    )
    assert bad.returncode == 2


def test_set_up_installs_nothing_into_the_users_desktop(tmp_path: Path) -> None:
    """The desktop entry is the operator's choice (``rtmu --install-desktop``), never a set-up side effect."""
    home = tmp_path / "home"
    home.mkdir()
    command = (
        "source scripts/setup.sh; ensure_system_packages() { :; }; ensure_venv() { :; }; "
        "ensure_project() { :; }; main"
    )
    env = {"PATH": os.environ["PATH"], "HOME": str(home), "XDG_DATA_HOME": str(home / "data")}
    result = subprocess.run(
        ["bash", "-c", command], cwd=ROOT, env=env, capture_output=True, text=True, timeout=30
    )
    assert result.returncode == 0, result.stderr
    assert list(home.iterdir()) == [], "scripts/setup.sh wrote into the user's home"
