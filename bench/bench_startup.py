"""What a command costs before it does anything: CPU seconds from exec to exit, per process.

Every figure is the median of a few runs of a fresh process, measured with ``wait4``'s resource
usage (user + system CPU of that process alone), interleaved with its baseline so both see the same
load on a shared machine; the bytecode is cached first, as an installed RTMU has it. The simulator
runs in a process of its own (office map, no camera).

* ``startup.version_cpu_s`` (s): ``rtmu --version``. Baseline: ``python -c pass`` (the interpreter's
  own start). Target ≤ 0.15 s.
* ``startup.help_cpu_s.max`` / ``.median`` (s): ``rtmu SUB --help`` for every subcommand (the most
  expensive one, and the middle one). Same baseline, same target.
* ``startup.status_once_cpu_s`` (s): ``rtmu status --once`` against the simulator, end to end (start,
  login, one status, exit). Baseline: ARIA's own C++ ``clientCommandLister`` against the same
  simulator (log in, list the data, exit) where it is built (``/work/realpeer``), else none.
  Target ≤ 0.3 s.
* ``startup.probe_cpu_s`` (s): ``rtmu probe`` against the simulator; the same baseline.
* ``startup.guardian_cpu_s`` (s): a guardian process (``python -m rtmu.guardian``, as the window and
  ``rtmu drive`` start one) from exec until it has logged in and said ``ready``. Baseline: as for
  status. Target ≤ 0.2 s.
* ``startup.window_modules_cpu_s`` (s): a fresh interpreter importing everything the window needs
  (``rtmu.ui.application``), the compiled dataclass methods read from a warm cache
  (``base.dataclass_code``, as after the window's first start). Baseline: the same import without the
  cache (every dataclass compiles its methods again, as before it).
* ``startup.guardian_rss_mib`` (MiB): the guardian's peak resident memory by then. Baseline: the peak
  of ``python -c pass``.
"""

from __future__ import annotations

import contextlib
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

from bench.common import Result, as_installed, cache_bytecode, end_process
from rtmu.package_data import project_map
from rtmu.values.target import Target

RUNS = 5
HELP_RUNS = 2
REPO = Path(__file__).resolve().parents[1]
ARIA = Path("/work/realpeer/aria")
COMMAND_LISTER = ARIA / "ArNetworking/examples/clientCommandLister"
PYTHON = sys.executable
TICKS = os.sysconf("SC_CLK_TCK")
INSTALL_CACHE = "from rtmu.base import dataclass_code\ndataclass_code.install()"


def _env(**extra: str) -> dict[str, str]:
    env = as_installed(dict(os.environ))
    env.update(extra)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO / "src"), env.get("PYTHONPATH", "")) if p)
    env["LD_LIBRARY_PATH"] = os.pathsep.join(
        p for p in (str(ARIA / "lib"), env.get("LD_LIBRARY_PATH", "")) if p
    )
    return env


def cpu_of(argv: Sequence[str], env: dict[str, str] | None = None) -> tuple[float, float]:
    """(user + system CPU seconds, peak RSS in MiB) of one run of ``argv``, output thrown away."""
    proc = subprocess.Popen(
        argv,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env or _env(),
    )
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def median_cpu(argv: Sequence[str], runs: int = RUNS) -> float:
    return statistics.median(cpu_of(argv)[0] for _ in range(runs))


def interleaved(a: Sequence[str], b: Sequence[str], runs: int = RUNS) -> tuple[float, float]:
    """Medians of ``a`` and ``b`` run turn about (A B A B …), so both see the same load."""
    ta: list[float] = []
    tb: list[float] = []
    for _ in range(runs):
        ta.append(cpu_of(a)[0])
        tb.append(cpu_of(b)[0])
    return statistics.median(ta), statistics.median(tb)


def window_modules() -> tuple[float, float]:
    """(CPU of importing the window's modules with a warm dataclass cache, the same without it)."""
    with tempfile.TemporaryDirectory(prefix="rtmu-bench-cache-") as cache:
        env = _env(XDG_CACHE_HOME=cache, OPENBLAS_NUM_THREADS="1")
        cached = [
            PYTHON,
            "-c",
            "from rtmu.base import dataclass_code as d\nd.install()\nimport rtmu.ui.application",
        ]
        stock = [PYTHON, "-c", "import rtmu.ui.application"]
        cpu_of(cached, env)  # the first start fills the cache
        ours: list[float] = []
        theirs: list[float] = []
        for _ in range(RUNS):
            ours.append(cpu_of(cached, env)[0])
            theirs.append(cpu_of(stock, env)[0])
    return statistics.median(ours), statistics.median(theirs)


@contextlib.contextmanager
def simulator() -> Iterator[int]:
    """``rtmu sim`` on a free port (office map, no camera), in its own process; yields the port."""
    sim = subprocess.Popen(
        [PYTHON, "-m", "rtmu", "sim", "--port", "0", "--map", str(project_map("office.map")), "--no-camera"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=_env(),
    )
    try:
        assert sim.stdout is not None
        line = sim.stdout.readline()
        found = re.search(r"127\.0\.0\.1:(\d+)", line)
        if found is None:
            raise RuntimeError(f"the simulator did not say its port: {line!r}")
        yield int(found.group(1))
    finally:
        end_process(sim)


def subcommands() -> list[str]:
    out = subprocess.run(
        [PYTHON, "-c", "from rtmu.cli import subcommand_names; print(*subcommand_names())"],
        capture_output=True,
        text=True,
        env=_env(),
        check=False,
    )
    if out.returncode != 0:  # an older tree: every module of the package is a subcommand
        names = [p.stem for p in (REPO / "src/rtmu/subcommands").glob("*.py")]
        return sorted(n for n in names if not n.startswith("_"))
    return out.stdout.split()


def _proc_cpu(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def _proc_peak_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmHWM")


def guardian_start(port: int) -> tuple[float, float]:
    """(CPU seconds, peak RSS MiB) of one guardian from exec until it said ``ready``."""
    from rtmu.guardian.handle import GuardianHandle
    from rtmu.guardian.messages import Hello

    kept = os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # the guardian inherits our environment
    try:
        handle = GuardianHandle.start(Hello(Target("127.0.0.1", port)))
    finally:
        if kept is not None:
            os.environ["PYTHONDONTWRITEBYTECODE"] = kept
    try:
        deadline = time.monotonic() + 60
        while handle.state == "starting":
            handle.poll()
            if time.monotonic() > deadline:
                raise RuntimeError("the guardian did not log in in time")
            time.sleep(0.005)
        if handle.state != "ready":
            raise RuntimeError(f"the guardian did not start: {handle.reason}")
        return _proc_cpu(handle.proc.pid), _proc_peak_mib(handle.proc.pid)
    finally:
        handle.close(goodbye=True)
        with contextlib.suppress(subprocess.TimeoutExpired):
            handle.proc.wait(10)


def run() -> list[Result]:
    cache_bytecode()
    rtmu = [PYTHON, "-m", "rtmu"]
    bare = [PYTHON, "-c", "pass"]
    version, bare_cpu = interleaved([*rtmu, "--version"], bare)
    helps = {name: median_cpu([*rtmu, name, "--help"], HELP_RUNS) for name in subcommands()}
    worst = max(helps, key=helps.__getitem__)
    print(f"# startup: most expensive --help: {worst} ({helps[worst]:.3f} s)", file=sys.stderr)
    results = [
        Result("startup.version_cpu_s", version, "s", bare_cpu),
        Result("startup.help_cpu_s.max", helps[worst], "s", bare_cpu),
        Result("startup.help_cpu_s.median", statistics.median(helps.values()), "s", bare_cpu),
    ]
    modules, modules_stock = window_modules()
    results.append(Result("startup.window_modules_cpu_s", modules, "s", modules_stock))
    aria = COMMAND_LISTER.exists()
    with simulator() as port:
        lister = [str(COMMAND_LISTER), "-host", "127.0.0.1", "-port", str(port)]
        for name, argv in (
            ("status_once", [*rtmu, "status", "--once", f"127.0.0.1:{port}"]),
            ("probe", [*rtmu, "probe", f"127.0.0.1:{port}"]),
        ):
            if aria:
                ours, theirs = interleaved(argv, lister)
            else:
                ours, theirs = median_cpu(argv), None
            results.append(Result(f"startup.{name}_cpu_s", ours, "s", theirs))
        starts = [guardian_start(port) for _ in range(RUNS)]
        lister_cpu = median_cpu(lister) if aria else None
    bare_rss = statistics.median(cpu_of(bare)[1] for _ in range(3))
    results += [
        Result("startup.guardian_cpu_s", statistics.median(s[0] for s in starts), "s", lister_cpu),
        Result("startup.guardian_rss_mib", statistics.median(s[1] for s in starts), "MiB", bare_rss),
    ]
    return results
