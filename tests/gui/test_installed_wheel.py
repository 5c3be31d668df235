"""The wheel as a user gets it: installed into a fresh virtualenv with only the system's packages beside
it (as pipx does), ``rtmu --version``, ``rtmu sim --help`` and a short ``rtmu --demo`` on this run's
Xvfb and session bus, ended by SIGTERM, which must end it cleanly.

Nothing of the checkout is on the path: the venv's ``rtmu`` runs from site-packages, with the maps
and files the wheel carries. Dependencies come from the package index at the versions in
constraints.txt (pip's cache keeps the PyGObject and pycairo it builds for the next run).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rtmu import __version__
from run_once import run_once

from .process import screenshot, wait

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow


def clean_env(**extra: str) -> dict[str, str]:
    """This run's environment (display, bus, data folders) without anything pointing into the checkout."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    venv_bin = str(Path(sys.prefix) / "bin")
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if p != venv_bin)
    return {**env, **extra}


@pytest.fixture(scope="module")
def installed(built_dists: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh ``--system-site-packages`` venv with the wheel installed: its ``bin`` folder (made once a
    run, ``run_once``: this module's tests may run in different workers)."""
    _, wheel = built_dists
    (bin_dir,) = run_once(tmp_path_factory, "wheel-venv", lambda folder: [install_wheel(wheel, folder)])
    return bin_dir


def install_wheel(wheel: Path, folder: Path) -> Path:
    """A ``--system-site-packages`` venv in ``folder`` with ``wheel`` installed: its ``bin`` folder."""
    venv = folder / "venv"
    base = getattr(sys, "_base_executable", sys.executable)
    make = subprocess.run(
        [base, "-m", "venv", "--system-site-packages", str(venv)], capture_output=True, text=True, timeout=300
    )
    assert make.returncode == 0, make.stderr
    install = subprocess.run(
        [
            str(venv / "bin" / "python"),
            "-m",
            "pip",
            "install",
            "-q",
            "--disable-pip-version-check",
            "-c",
            str(ROOT / "constraints.txt"),
            str(wheel),
        ],
        capture_output=True,
        text=True,
        timeout=1800,
        env=clean_env(),
        cwd=venv,
    )
    assert install.returncode == 0, install.stdout[-3000:] + install.stderr[-3000:]
    return venv / "bin"


def run(bin_dir: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(bin_dir / "rtmu"), *argv],
        capture_output=True,
        text=True,
        timeout=120,
        env=clean_env(),
        cwd=bin_dir,
    )


def test_the_installed_rtmu_runs_from_the_venv_not_the_checkout(installed: Path) -> None:
    where = subprocess.run(
        [
            str(installed / "python"),
            "-c",
            "import rtmu, rtmu.package_data as d; print(rtmu.__file__); print(d.MAPS_DIR)",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env=clean_env(),
        cwd=installed,
    )
    assert where.returncode == 0, where.stderr
    module, maps = where.stdout.split()
    assert Path(module).is_relative_to(installed.parent) and not Path(module).is_relative_to(ROOT)
    assert (Path(maps) / "office.map").is_file() and (Path(maps) / "arena.map").is_file()


def test_version_and_sim_help(installed: Path) -> None:
    version = run(installed, "--version")
    assert version.returncode == 0, version.stderr
    lines = version.stdout.splitlines()
    assert lines[0] == f"rtmu {__version__}" and "GTK 4." in lines[2] and "PyGObject 3." in lines[2]
    sim_help = run(installed, "sim", "--help")
    assert sim_help.returncode == 0, sim_help.stderr
    assert sim_help.stdout.startswith("usage: rtmu sim")


def test_a_short_demo_opens_the_window_and_ends_cleanly_on_sigterm(
    installed: Path, tmp_path: Path, screenshots: Path
) -> None:
    env = clean_env(XDG_CONFIG_HOME=str(tmp_path / "config"), XDG_DATA_HOME=str(tmp_path / "data"))
    proc = subprocess.Popen(
        [str(installed / "rtmu"), "--demo"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    try:
        window = ""

        def mapped() -> bool:
            nonlocal window
            found = subprocess.run(
                ["xdotool", "search", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU"],
                capture_output=True,
                text=True,
                timeout=15,
            )
            window = found.stdout.split()[0] if found.stdout.split() else ""
            return bool(window) or proc.poll() is not None

        wait(mapped, 90, "the demo window", poll=0.2)
        assert proc.poll() is None, f"rtmu --demo ended early: {proc.stderr.read() if proc.stderr else ''}"
        time.sleep(3)  # a few seconds of the demo: connected, map and robot drawn
        screenshot(screenshots / "installed-wheel-demo.png", window)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "CRITICAL" not in err, err
    assert "Unable to acquire session bus" not in err, err
