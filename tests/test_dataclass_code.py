"""base.dataclass_code: a second start compiles no dataclass method, and the classes are the same.

Each case runs fresh interpreters (the cache is read once per process) with a cache folder of its
own; compilations are counted, never timed.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import rtmu
from rtmu.package_data import project_map

SRC = Path(rtmu.__file__).resolve().parents[1]

PROBE = """
import dataclasses, json, os
from rtmu.base import dataclass_code
if not os.environ.get("STOCK"):
    dataclass_code.install()
import rtmu.values.intents as intents
import rtmu.values.state as state


def fingerprint(cls):
    out = {}
    for name in ("__init__", "__repr__", "__eq__", "__hash__", "__setattr__", "__delattr__"):
        fn = cls.__dict__.get(name)
        code = getattr(fn, "__code__", None) or getattr(getattr(fn, "__wrapped__", None), "__code__", None)
        if code is not None:
            notes = {k: repr(v) for k, v in getattr(fn, "__annotations__", {}).items()}
            out[name] = [code.co_code.hex(), repr(code.co_consts), code.co_names, code.co_flags, notes]
    return out


classes = [c for m in (intents, state) for c in vars(m).values()
           if isinstance(c, type) and dataclasses.is_dataclass(c) and c.__module__ == m.__name__]

@dataclasses.dataclass(frozen=True, slots=True)
class Probe:
    a: int
    b: tuple[str, ...] = ()

p = Probe(1, ("x",))
try:
    p.a = 2
    frozen = False
except dataclasses.FrozenInstanceError:
    frozen = True
print(json.dumps({
    "new": dataclass_code.compiled_this_run(),
    "repr": repr(p),
    "eq": p == Probe(1, ("x",)) and p != Probe(2),
    "hash": hash(p) == hash(Probe(1, ("x",))),
    "frozen": frozen,
    "fields": [f.name for f in dataclasses.fields(intents.GotoPose)],
    "default": repr(Probe(3)),
    "annotations": {k: getattr(v, "__name__", repr(v)) for k, v in Probe.__init__.__annotations__.items()},
    "methods": {c.__qualname__: fingerprint(c) for c in classes},
}))
"""


def run_probe(cache: Path, *, stock: bool = False) -> dict[str, object]:
    env = {**os.environ, "PYTHONPATH": str(SRC), "XDG_CACHE_HOME": str(cache), "STOCK": "1" if stock else ""}
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    return dict(json.loads(out.stdout.splitlines()[-1]))


def test_a_second_start_compiles_nothing_and_makes_the_same_classes(tmp_path: Path) -> None:
    first = run_probe(tmp_path)
    assert isinstance(first["new"], int) and first["new"] > 20  # intents alone makes dozens of methods
    assert list((tmp_path / "rtmu").glob("dataclass-code-*.marshal"))
    second = run_probe(tmp_path)
    assert second["new"] == 0
    assert {k: v for k, v in second.items() if k != "new"} == {k: v for k, v in first.items() if k != "new"}
    assert first["repr"] == "Probe(a=1, b=('x',))" and first["default"] == "Probe(a=3, b=())"
    assert first["eq"] and first["hash"] and first["frozen"]
    # __init__'s annotations are the types, as the stock dataclasses makes them (not strings)
    assert first["annotations"] == second["annotations"] == {"a": "int", "b": "tuple", "return": "None"}


def test_the_methods_are_those_the_stock_dataclasses_makes(tmp_path: Path) -> None:
    """Bytecode, constants, names, flags and annotations of every generated method of the intents
    and the state, compiled (first run) and read back (second), equal a run without the cache."""
    stock = run_probe(tmp_path / "unused", stock=True)["methods"]
    assert isinstance(stock, dict) and len(stock) > 40
    assert run_probe(tmp_path)["methods"] == stock
    assert run_probe(tmp_path)["methods"] == stock


def test_a_damaged_cache_costs_compilations_only_and_is_written_again(tmp_path: Path) -> None:
    run_probe(tmp_path)
    (cached,) = (tmp_path / "rtmu").glob("dataclass-code-*.marshal")
    cached.write_bytes(b"\x00not marshal at all" * 100)
    again = run_probe(tmp_path)
    assert isinstance(again["new"], int) and again["new"] > 20
    assert again["frozen"] and again["eq"]
    assert run_probe(tmp_path)["new"] == 0  # the damaged file was replaced by a good one


def test_a_cache_of_the_wrong_shape_costs_compilations_only(tmp_path: Path) -> None:
    """Files marshal reads but RTMU never wrote: each is ignored (entry by entry where it can)."""
    import marshal

    cached = cache_path(tmp_path)
    cached.parent.mkdir(parents=True)
    for table in (
        ({b"k" * 20: 5, b"j" * 20: (1, 2, 3), b"i" * 20: ("a", 1), 7: (0, 1), b"h" * 20: (4, 99)}, b"blob"),
        ([1, 2], b""),
        ("text", 3),
        (1, 2, 3),
        {"a": 1},
    ):
        cached.write_bytes(marshal.dumps(table))
        result = run_probe(tmp_path)
        assert result["frozen"] and result["eq"], table
        assert isinstance(result["new"], int) and result["new"] > 20


def cache_path(cache_home: Path) -> Path:
    """The cache file a probe run with ``XDG_CACHE_HOME=cache_home`` reads (named as the module says)."""
    env = {**os.environ, "PYTHONPATH": str(SRC), "XDG_CACHE_HOME": str(cache_home)}
    code = "from rtmu.base import dataclass_code\nprint(dataclass_code.cache_file())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
    return Path(out.stdout.strip())


def test_an_unwritable_cache_is_skipped_quietly(tmp_path: Path) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the cache folder would go")
    result = run_probe(blocker)
    assert result["frozen"] and result["eq"]
    assert blocker.read_text() == "a file where the cache folder would go"


def test_the_rtmu_command_installs_it(tmp_path: Path) -> None:
    """``rtmu`` (cli.main) installs the cache before a command's handler loads its modules:
    ``rtmu mapinfo`` leaves a cache file behind; ``rtmu --version`` neither loads ``dataclasses`` nor
    writes one."""
    env = {**os.environ, "PYTHONPATH": str(SRC), "XDG_CACHE_HOME": str(tmp_path)}
    version = (
        "import sys\nfrom rtmu.cli import main\ntry:\n    main(['--version'])\nexcept SystemExit:\n    pass\n"
        "assert 'dataclasses' not in sys.modules, 'dataclasses loaded by --version'\n"
    )
    out = subprocess.run([sys.executable, "-c", version], capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 0, out.stderr[-2000:]
    assert not (tmp_path / "rtmu").exists()
    office = project_map("office.map")
    code = f"from rtmu.cli import main\nmain(['mapinfo', {str(office)!r}])\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert list((tmp_path / "rtmu").glob("dataclass-code-*.marshal"))


def test_release_saves_lets_go_of_the_table_and_later_classes_still_work(tmp_path: Path) -> None:
    run_probe(tmp_path)  # a cache to read
    code = (
        "import dataclasses, json\nfrom rtmu.base import dataclass_code as d\nd.install()\n"
        "import rtmu.values.intents\nheld = d.held_entries()\nd.release()\n"
        "@dataclasses.dataclass(frozen=True)\nclass Late:\n    x: int = 4\n"
        "print(json.dumps([held, d.held_entries(), repr(Late()), Late() == Late(4)]))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC), "XDG_CACHE_HOME": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    held, after, late_repr, late_eq = json.loads(out.stdout.splitlines()[-1])
    assert held > 20 and after == 0
    assert late_repr == "Late(x=4)" and late_eq
