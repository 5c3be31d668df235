"""The operator window's benchmark figures: names that say what they are, the speed-up the right way round."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # bench/ is a folder of the checkout, not an installed package
    sys.path.insert(0, str(REPO))
from bench.bench_ui import frame_results  # noqa: E402


def test_frame_figures_keep_their_shape_and_state_the_speed_up_plainly() -> None:
    ms = 1e-3
    figures = {
        r.name: r for r in frame_results([0.5 * ms] * 10, [1.0 * ms] * 10, [800 * ms] * 3, [6000 * ms] * 3)
    }
    p50 = figures["ui.frame_ms.1m_follow_100pct.p50"]
    assert (p50.value, p50.unit, p50.baseline) == (pytest.approx(0.5), "ms", pytest.approx(800))
    assert p50.as_json()["ratio"] == pytest.approx(0.5 / 800, abs=1e-4), (
        "ratio = value / baseline, as common.py"
    )
    follow = figures["ui.frame_speedup.1m_follow_100pct.p50"]
    fit = figures["ui.frame_speedup.1m_fit.p95"]
    assert (follow.unit, fit.unit) == ("x", "x")
    assert follow.value == pytest.approx(1600) and fit.value == pytest.approx(6000)
    assert follow.baseline is None and "ratio" not in follow.as_json()
