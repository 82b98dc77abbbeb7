"""Gaze-aware LiDAR in CARLA's synchronous mode.

The client ticks the world at the LiDAR's frame period, so each
`sensor.lidar.ray_cast` measurement is exactly one turn; the listen callback
only queues the measurement, and the main loop, after each `world.tick()`,
feeds the tracker's samples to the GazeStream, runs its frame clock to the
measurement's timestamp, and keeps the points the gaze-adaptive sensor would
return (`gaze_lidar.carla.apply_to_measurement`).

Run it against a CARLA server (`python carla_sync.py`, needs the `carla`
package); `process()` is the CARLA-free part, tested on synthetic
measurements laid out as CARLA's.
"""

from __future__ import annotations

import queue
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

import gaze_lidar as gl
from gaze_lidar import carla as glc

#: (t_s, gaze_deg, valid) samples since the last call, on the simulation clock.
GazeSource = Callable[[], Sequence[tuple[float, float, bool]]]


class AdaptiveLidar:
    """One GazeStream and the frame in force; `process` is called once per
    measurement (any thread: the stream has its own lock)."""

    def __init__(self, *, sensor_transform: Any = None, mode: str = "range", rated_range_m: float = 100.0) -> None:
        self.stream = gl.GazeStream(preset="paper", mode=mode, timeout_ms=100)  # type: ignore[arg-type]
        self.sensor_transform = sensor_transform
        self.rated_range_m = rated_range_m
        self.frame: gl.Frame | None = None
        self.sweeps = 0

    def process(self, measurement: Any, timestamp_s: float, gaze: Sequence[tuple[float, float, bool]]) -> npt.NDArray[Any]:
        """The kept points of one measurement (rows of `points_from_measurement`)."""
        if gaze:
            t, g, v = (np.asarray(c) for c in zip(*gaze))
            for f in self.stream.push_many(t, g, v):
                self.frame = f
        for f in self.stream.tick(timestamp_s):  # silence still yields frames
            self.frame = f
        points = glc.points_from_measurement(measurement)
        if self.frame is None:  # before the first frame nothing is certified
            return points[:0]
        keep = glc.apply_to_measurement(
            self.frame.profile,
            measurement,
            rated_range_m=self.rated_range_m,
            sensor_transform=self.sensor_transform,
            seed=self.sweeps,  # fresh thinning draws each sweep, reproducible
        )
        self.sweeps += 1
        return points[keep]


def main(gaze_source: GazeSource, frames: int = 200) -> None:  # pragma: no cover - needs a CARLA server
    import carla  # type: ignore[import-not-found]

    client = carla.Client("localhost", 2000)
    world = client.get_world()
    profile = gl.profile(mode="baseline", gaze_deg=None)
    settings = world.get_settings()
    settings.synchronous_mode = True
    settings.fixed_delta_seconds = 1.0 / profile.frame_rate_hz  # one turn per tick
    world.apply_settings(settings)
    bp = world.get_blueprint_library().find("sensor.lidar.ray_cast")
    bp.set_attribute("rotation_frequency", str(profile.frame_rate_hz))
    bp.set_attribute("dropoff_general_rate", "0")
    bp.set_attribute("dropoff_zero_intensity", "0")
    bp.set_attribute("range", "200")  # record beyond the rated range
    glc.check_blueprint(bp, profile, fixed_delta_seconds=settings.fixed_delta_seconds)
    ego = world.get_actors().filter("vehicle.*")[0]
    mount = carla.Transform(carla.Location(z=2.0))
    lidar = world.spawn_actor(bp, mount, attach_to=ego)
    measurements: queue.Queue[Any] = queue.Queue()
    lidar.listen(measurements.put)
    adaptive = AdaptiveLidar(sensor_transform=mount)
    try:
        for _ in range(frames):
            world.tick()
            m = measurements.get(timeout=2.0)
            kept = adaptive.process(m, m.timestamp, gaze_source())
            state = adaptive.frame.state if adaptive.frame else "none"
            print(f"frame {m.frame}: {state}, kept {len(kept)} of {len(m)} points")
    finally:
        lidar.stop()
        lidar.destroy()
        settings.synchronous_mode = False
        world.apply_settings(settings)


if __name__ == "__main__":  # pragma: no cover
    main(lambda: [])
