"""examples/python/carla_sync.py and carla_async.py on synthetic CARLA
measurements (no carla install): a driver looking left for 0.3 s, then lost."""

from __future__ import annotations

import importlib.util
import pathlib
import queue
import threading
from types import ModuleType
from typing import Any

import numpy as np
import numpy.typing as npt

import gaze_lidar as gl


def load(repo: pathlib.Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, repo / f"examples/python/{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Measurement:
    """carla.LidarMeasurement's surface: raw_data, len(), timestamp, frame."""

    def __init__(self, frame: int, timestamp: float, rng: np.random.Generator, n: int = 20_000) -> None:
        az = np.radians(rng.uniform(0, 360, n))
        r = rng.uniform(2, 150, n)
        pts = np.zeros((n, 4), dtype="<f4")
        pts[:, 0], pts[:, 1] = r * np.cos(az), -r * np.sin(az)
        self.raw_data = memoryview(pts.tobytes())
        self.frame, self.timestamp, self._n = frame, timestamp, n

    def __len__(self) -> int:
        return self._n


def max_range(kept: npt.NDArray[Any], lo: float, hi: float) -> float:
    az = gl.azimuth_deg(kept)
    r = np.linalg.norm(kept[:, :3].astype(np.float64), axis=1)
    sel = (az > lo) & (az < hi)
    return float(r[sel].max()) if sel.any() else 0.0


def test_sync_example(repo: pathlib.Path) -> None:
    mod = load(repo, "carla_sync")
    lidar = mod.AdaptiveLidar()
    rng = np.random.default_rng(1)
    states = []
    for k in range(10):
        t = k * 0.05
        gaze = [(float(s), 90.0, bool(s < 0.3)) for s in np.arange(max(t - 0.05, 0.0), t, 0.005)]
        kept = lidar.process(Measurement(k, t, rng), t, gaze)
        states.append(lidar.frame.state if lidar.frame else "none")
        if states[-1] == "adaptive":
            assert max_range(kept, 60, 120) < 72.0 < 104.0 < max_range(kept, 240, 300)
    assert states[0] == "fail_safe" and "adaptive" in states and states[-1] == "fail_safe"


def test_async_example_from_carlas_thread(repo: pathlib.Path) -> None:
    mod = load(repo, "carla_async")
    stream = gl.GazeStream()
    results: queue.Queue[tuple[float, str, Any]] = queue.Queue()
    callback = mod.make_callback(stream, results)
    rng = np.random.default_rng(2)
    measurements = [Measurement(k, k * 0.05, rng) for k in range(10)]
    errors: list[BaseException] = []

    def carla_thread() -> None:  # CARLA calls listen callbacks on its own thread
        try:
            for m in measurements:
                t = m.timestamp
                s = np.arange(max(t - 0.05, 0.0), t, 0.005)
                stream.push_many(s, np.full(s.size, 90.0), s < 0.3)  # the tracker's samples
                callback(m)
        except BaseException as e:  # noqa: BLE001
            errors.append(e)

    t = threading.Thread(target=carla_thread)
    t.start()
    t.join(120)
    assert errors == []
    got = [results.get_nowait() for _ in measurements]
    states = [s for _, s, _ in got]
    assert states[0] == "fail_safe" and "adaptive" in states and states[-1] == "fail_safe"
    for _, state, kept in got:
        if state == "adaptive":
            assert max_range(kept, 60, 120) < 72.0 < 104.0 < max_range(kept, 240, 300)
