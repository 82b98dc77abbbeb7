"""examples/python/carla_callback.py runs on a synthetic cloud."""

from __future__ import annotations

import pathlib
from types import ModuleType
import importlib.util

import numpy as np


def load(repo: pathlib.Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location("carla_callback", repo / "examples/python/carla_callback.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_callback_adapts_then_falls_back_when_the_eyes_are_lost(repo: pathlib.Path) -> None:
    rows = load(repo).demo(sweeps=10, seed=4)
    states = [r["state"] for r in rows]
    # No gaze at the first frame; adaptive while the driver looks left;
    # fail-safe at the first frame after the tracker loses the eyes (0.3 s).
    assert states == ["fail_safe"] + ["adaptive"] * 6 + ["fail_safe"] * 3
    for r in rows:
        if r["state"] == "adaptive":
            assert r["max_range_left_m"] < 72.0 < 104.0 < r["max_range_right_m"]
        else:
            assert 99.0 < r["max_range_left_m"] <= 100.0 and 99.0 < r["max_range_right_m"] <= 100.0


def test_points_from_raw_is_carlas_layout(repo: pathlib.Path) -> None:
    mod = load(repo)
    raw = np.arange(8, dtype=np.float32).tobytes()
    pts = mod.points_from_raw(raw)
    assert pts.shape == (2, 4) and pts.dtype == np.float32 and pts[1, 0] == 4.0
