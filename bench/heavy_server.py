"""``python -m bench.heavy_server KIND``: one of ``tests/client/heavy_servers.py`` in its own process
(``drawings``, ``frames``, ``popups`` or ``plain``), reporting the drive packets it hears (see there)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from client.heavy_servers import main

if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1]))
