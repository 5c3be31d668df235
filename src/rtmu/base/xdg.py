"""The user's folders as the XDG base directory specification names them: one rule for every file
RTMU keeps — settings, recordings, the last doctor report, the desktop files, the compiled-code cache.

The variable's value when it is an absolute path; otherwise (unset, empty or relative: the spec says
a relative one is to be ignored) the spec's default under the home folder.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

CONFIG = ("XDG_CONFIG_HOME", ".config")
DATA = ("XDG_DATA_HOME", ".local/share")
CACHE = ("XDG_CACHE_HOME", ".cache")


def xdg_home(which: tuple[str, str], env: Mapping[str, str] | None = None) -> Path:
    """The folder for ``which`` (:data:`CONFIG`, :data:`DATA` or :data:`CACHE`), read from ``env``
    (default: this process's environment)."""
    variable, default = which
    value = (os.environ if env is None else env).get(variable, "")
    return Path(value) if value and os.path.isabs(value) else Path.home() / default
