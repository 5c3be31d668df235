"""``scripts/i18n.py`` (the translations' tooling, ``./rtmu-dev i18n``) loaded as a module for the tests."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "i18n.py"


def _load() -> ModuleType:
    spec = importlib.util.spec_from_file_location("rtmu_i18n_tooling", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


tooling = sys.modules.get("rtmu_i18n_tooling") or _load()
