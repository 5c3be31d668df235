"""Sphinx configuration of RTMU's documentation: ``./rtmu-dev docs`` builds it, the suite builds it with
warnings as errors (tests/test_docs.py). Pages are Markdown (MyST); the CLI reference is read from the
command's own argparse parser (``_ext/cli_reference.py``), the exit codes from ``rtmu.base.exit_codes``
(``_ext/exit_code_table.py``)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))

from rtmu import __version__

project = "RTMU"
author = "The RTMU developers"
copyright = "2026, The RTMU developers"
version = release = __version__

extensions = ["myst_parser", "cli_reference", "exit_code_table"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "_ext"]
myst_heading_anchors = 3
myst_enable_extensions = ["deflist"]
html_theme = "alabaster"
html_title = f"RTMU {__version__}"
html_static_path: list[str] = []
