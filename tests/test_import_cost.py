"""What starting a command loads: counted in fresh interpreters, never timed (issue 28).

``rtmu --version``, every ``rtmu SUB --help``, a script's ``rtmu status --once`` and each guardian
process pay their imports at every start. numpy, GTK, PIL, scikit-image, the recorder (foxglove-sdk,
mcap) and — for the command line — asyncio and the connection are imported by the code that needs
them, when it runs; these tests fail the day a module-level import pulls one of them in again, and
name the chain that did.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import rtmu
from rtmu.cli import subcommand_names

SRC = Path(rtmu.__file__).resolve().parents[1]

HEAVY = ("numpy", "gi", "PIL", "skimage", "scipy", "foxglove", "mcap", "cairo")
"""Never loaded by these entry points (GTK comes in through ``gi``)."""
RECORDER_INSIDE = ("rtmu.recorder.",)
"""The recorder's modules (its package and ``topics`` are names only; see ``rtmu/recorder/__init__``)."""
RECORDER_LIGHT = ("rtmu.recorder.topics", "rtmu.recorder.foxglove_gate")
"""Recorder modules of the standard library alone: topic names, the bridge's handshake rules (whose
origins ``rtmu bridge --help`` names)."""
NETWORK = ("asyncio", "rtmu.client.connection", "rtmu.client.runner", "rtmu.client.session", "rtmu.sim.")
"""What a parser needs no part of: the command that runs loads it."""


def loaded_by(code: str) -> list[str]:
    """The modules in ``sys.modules`` after running ``code`` in a fresh interpreter (this tree first)."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))\n"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    return list(json.loads(out.stdout.splitlines()[-1]))


def offending(modules: list[str], *, network: bool) -> list[str]:
    bad = [m for m in modules if m.split(".")[0] in HEAVY]
    bad += [m for m in modules if m.startswith(RECORDER_INSIDE) and m not in RECORDER_LIGHT]
    if network:
        bad += [m for m in modules if m == "asyncio" or m.startswith(NETWORK)]
    return bad


def why(module: str, code: str) -> str:
    """Who imported ``module`` first, as ``-X importtime`` nests it (for the failure message)."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", code], capture_output=True, text=True,
                         env=env, timeout=120)  # fmt: skip
    lines = [line.split("|")[-1].rstrip() for line in out.stderr.splitlines() if "|" in line]
    for i, line in enumerate(lines):
        if line.strip() == module:
            depth = len(line) - len(line.lstrip())
            chain = [line.strip()]
            for later in lines[i + 1 :]:  # importtime prints a module after what it imported
                d = len(later) - len(later.lstrip())
                if d < depth:
                    chain.append(later.strip())
                    depth = d
            return " ← ".join(chain)
    return module


def run_main(argv: list[str]) -> str:
    """Code that runs ``rtmu ARGV`` (its output and exit swallowed)."""
    return (
        "import contextlib, io\nfrom rtmu.cli import main\n"
        f"with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()): main({argv!r})"
    )


def check(code: str, *, network: bool) -> list[str]:
    modules = loaded_by(code)
    bad = offending(modules, network=network)
    return [why(m, code) for m in bad[:3]] + ([f"… {len(bad) - 3} more"] if len(bad) > 3 else [])


def test_importing_rtmu_loads_nothing_else() -> None:
    modules = loaded_by("import rtmu")
    assert [m for m in modules if m.startswith("rtmu")] == ["rtmu"]


def test_the_command_line_and_every_subcommand_parser_stay_light() -> None:
    """``build_parser()`` imports every subcommand module (what ``rtmu --help`` does)."""
    assert check("from rtmu.cli import build_parser; build_parser()", network=True) == []


def test_version_imports_no_subcommand() -> None:
    modules = loaded_by(run_main(["--version"]))
    assert offending(modules, network=True) == []
    assert [
        m for m in modules if m.startswith("rtmu.subcommands.") and m != "rtmu.subcommands._integration"
    ] == []


@pytest.mark.parametrize("name", ["status", "drive", "bridge", "record", "video", "sim"])
def test_a_subcommand_help_loads_that_subcommand_only(name: str) -> None:
    modules = loaded_by(run_main([name, "--help"]))
    assert offending(modules, network=True) == []
    assert "rtmu.subcommands.json_schemas" not in modules, "the help names its schema from _schema_names"
    commands = set(subcommand_names())  # not the helpers (``_common``) nor the schemas' data module
    others = {m.split(".")[2] for m in modules if m.startswith("rtmu.subcommands.") and m.count(".") == 2}
    others = (others & commands) - {name}
    assert len(others) <= 1, f"rtmu {name} --help loads other subcommands: {sorted(others)}"  # video: image's


def test_status_loads_no_numpy_gtk_or_recorder() -> None:
    """What ``rtmu status --once`` needs: the connection and the status payloads, nothing heavy."""
    modules = (
        "subcommands.status", "client.connection", "client.ld_data", "client.robot_status",
        "protocol.payloads.robot",
    )  # fmt: skip
    code = "import " + ", ".join(f"rtmu.{m}" for m in modules)
    assert check(code, network=False) == []


def test_the_guardian_child_loads_no_numpy_gtk_or_recorder() -> None:
    assert check("import rtmu.guardian.child", network=False) == []


def test_the_window_loads_no_replay_reader() -> None:
    """The window's application module (all a live window needs) loads no MCAP reader: replay mode,
    the only user of the replay bar, imports it when a recording is opened."""
    modules = loaded_by("import rtmu.ui.application")
    assert "rtmu.ui.application" in modules  # the probe imported what it meant to
    late = [
        m
        for m in modules
        if m.split(".")[0] == "mcap" or m.startswith(("rtmu.ui.replay", "rtmu.recorder.replay"))
    ]
    assert not late, f"{late} loaded with the window ({why(late[0], 'import rtmu.ui.application')})"


WINDOW_LATE = (
    "rtmu.client.central",  # a central server's roster: for a central profile only
    "rtmu.client.why_gather",  # why won't it move?: its questions, rules and fixes when first asked
    "rtmu.client.why_fix",
    "rtmu.client.why",
    "rtmu.client.why_values",
    "rtmu.client.config_care",  # configuration care (factory values, reset, map switch): first used
    "rtmu.protocol.payloads.configcare",
    "xml.sax",  # XML escaping brings urllib and email: no part of the first frame needs them
    "urllib.request",
    "email",
    "rtmu.ui.about",  # the dialogs and pages a menu opens: each imported when it first opens
    "rtmu.ui.config_page",
    "rtmu.ui.console_page",
    "rtmu.ui.details",
    "rtmu.ui.files_page",
    "rtmu.ui.map_edit_window",
    "rtmu.ui.move_dialogs",
    "rtmu.ui.palette",
    "rtmu.ui.settings_dialog",
    "rtmu.ui.why_window",
    "rtmu.client.files_feed",  # the feeds that only answer the operator: with their first intent
    "rtmu.client.console_feed",
    "rtmu.client.console",
    "rtmu.client.download",
    "rtmu.client.upload",
    "rtmu.client.remote_files",  # the files' rules and payloads: a file, a scan named, a map switched
    "rtmu.protocol.payloads.files",
)
"""What a launch to the first map frame does without (issue 28: launch ≤ 0.6 s); each is imported
where it is first used."""


def test_the_window_loads_what_its_first_frame_needs_and_not_these() -> None:
    """Counted, never timed: each of these cost every launch milliseconds before the first map frame."""
    code = "import rtmu.ui.application"
    modules = loaded_by(code)
    assert "rtmu.ui.application" in modules
    late = [m for m in modules if m in WINDOW_LATE or m.startswith(tuple(f"{w}." for w in WINDOW_LATE))]
    assert not late, f"{late} loaded with the window ({why(late[0], code)})"


def test_numpy_starts_no_blas_threads_under_the_rtmu_command() -> None:
    """numpy's OpenBLAS starts a thread per core at import unless told not to; every ``rtmu`` entry
    tells it (``cli.SINGLE_BLAS_THREAD``), so a command that loads numpy stays one thread. Counted in
    ``/proc/self/task`` (Linux), in a fresh interpreter without the variable set."""
    code = (
        "import os\nfrom rtmu.cli import main\ntry:\n    main(['--version'])\nexcept SystemExit:\n    pass\n"
        "import numpy\n"
        "print('threads', len(os.listdir('/proc/self/task')))\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OPENBLAS", "OMP_"))}
    env["PYTHONPATH"] = str(SRC)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    threads = int(out.stdout.split("threads")[-1])
    assert threads == 1, f"{threads} threads after numpy loaded under rtmu (OpenBLAS threads not held)"


@pytest.mark.parametrize(
    ("name", "running_only"),
    [
        ("decode", ("rtmu.capture.reader", "rtmu.capture.session_decoder", "rtmu.subcommands._decode_run")),
        ("why", ("rtmu.client.why", "rtmu.client.why_gather")),
        ("goto", ("rtmu.subcommands._navigate",)),
        ("localize", ("rtmu.subcommands._navigate",)),
    ],
)
def test_a_help_loads_nothing_only_running_needs(name: str, running_only: tuple[str, ...]) -> None:
    """What only a running command needs is imported in its handler (issue 28: ``--help`` ≤ 0.15 s)."""
    modules = set(loaded_by(run_main([name, "--help"])))
    assert sorted(modules & set(running_only)) == [], f"rtmu {name} --help loads what only running needs"
