"""Gaze-aware LiDAR in CARLA's asynchronous mode: the work in the callback.

CARLA runs `sensor.listen` callbacks on its own thread. Here the callback
itself feeds the GazeStream (thread-safe: an internal lock, the GIL released
while it plans) and filters the cloud, then hands the result to the main
thread through a queue; the eye tracker may push samples from a third
thread at its own rate. Measurements arrive whenever the server produces
them: each may hold part of a turn or more than one, so the frame clock is
run to each measurement's timestamp.

Run it against a CARLA server (`python carla_async.py`, needs the `carla`
package); `make_callback()` is the CARLA-free part, tested on synthetic
measurements from a second thread.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from typing import Any

import numpy.typing as npt

import gaze_lidar as gl
from gaze_lidar import carla as glc


def make_callback(
    stream: gl.GazeStream,
    results: queue.Queue[tuple[float, str, npt.NDArray[Any]]],
    *,
    sensor_transform: Any = None,
    rated_range_m: float = 100.0,
) -> Callable[[Any], None]:
    """A listen callback: runs the frame clock to the measurement, filters
    it with the frame in force, and queues (timestamp, state, kept points)."""
    lock = threading.Lock()
    current: list[gl.Frame] = []

    def on_measurement(m: Any) -> None:
        frames = stream.tick(m.timestamp)
        with lock:
            if frames:
                current[:] = frames[-1:]
            frame = current[0] if current else None
        points = glc.points_from_measurement(m, copy=True)  # raw_data dies with the callback
        if frame is None:
            results.put((m.timestamp, "none", points[:0]))
            return
        keep = gl.apply_profile(
            frame.profile,
            points,
            rated_range_m=rated_range_m,
            sensor_yaw_deg=glc.sensor_yaw_deg(sensor_transform),
            seed=m.frame,
        )
        results.put((m.timestamp, frame.state, points[keep]))

    return on_measurement


def main(seconds: float = 10.0) -> None:  # pragma: no cover - needs a CARLA server
    import carla  # type: ignore[import-not-found]

    client = carla.Client("localhost", 2000)
    world = client.get_world()
    stream = gl.GazeStream(mode="range")
    bp = world.get_blueprint_library().find("sensor.lidar.ray_cast")
    bp.set_attribute("rotation_frequency", "20")
    bp.set_attribute("dropoff_general_rate", "0")
    bp.set_attribute("dropoff_zero_intensity", "0")
    glc.check_blueprint(bp, gl.profile())
    ego = world.get_actors().filter("vehicle.*")[0]
    mount = carla.Transform(carla.Location(z=2.0))
    lidar = world.spawn_actor(bp, mount, attach_to=ego)
    results: queue.Queue[tuple[float, str, npt.NDArray[Any]]] = queue.Queue()
    lidar.listen(make_callback(stream, results, sensor_transform=mount))
    # Your tracker thread calls stream.push(t_s, gaze_deg, valid) on the simulation clock.
    try:
        t_end = world.get_snapshot().timestamp.elapsed_seconds + seconds
        while True:
            t, state, kept = results.get(timeout=2.0)
            print(f"t={t:.3f} s {state}: kept {len(kept)} points")
            if t > t_end:
                break
    finally:
        lidar.stop()
        lidar.destroy()


if __name__ == "__main__":  # pragma: no cover
    main()
