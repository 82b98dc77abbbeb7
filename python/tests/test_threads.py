"""GazeStream off the main thread (CARLA calls `sensor.listen` callbacks on
its own thread), and no Rust panic reaching Python as a BaseException."""

from __future__ import annotations

import queue
import threading

import numpy as np

import gaze_lidar as gl


def drive(stream: gl.GazeStream, t0: float, n: int, gaze_deg: float) -> list[str]:
    states: list[str] = []
    for i in range(n):
        t = t0 + i * 0.01
        for f in stream.push(t, gaze_deg):
            states.append(f.state)
    return states


def test_stream_driven_from_a_second_thread() -> None:
    stream = gl.GazeStream()
    out: queue.Queue[object] = queue.Queue()

    def worker() -> None:
        try:
            out.put(drive(stream, 0.0, 50, 90.0))
        except BaseException as e:  # noqa: BLE001 - the test reports anything
            out.put(e)

    t = threading.Thread(target=worker)
    t.start()
    t.join(60)
    got = out.get_nowait()
    assert not isinstance(got, BaseException), got
    assert isinstance(got, list) and "adaptive" in got
    # The same stream, back on the main thread, continues where the worker left it.
    assert stream.stats["samples"] == 50
    frames = stream.tick(0.6)
    assert frames and all(f.state in ("adaptive", "fail_safe") for f in frames)
    # The same samples on the main thread give the same frames.
    assert drive(gl.GazeStream(), 0.0, 50, 90.0) == got


def test_two_threads_share_one_stream_like_a_callback_and_a_tracker() -> None:
    stream = gl.GazeStream()
    errors: list[BaseException] = []
    frames: list[gl.Frame] = []
    lock = threading.Lock()
    barrier = threading.Barrier(2)

    def tracker() -> None:
        try:
            barrier.wait()
            for i in range(300):
                got = stream.push(i * 0.002, 90.0)
                with lock:
                    frames.extend(got)
        except BaseException as e:  # noqa: BLE001
            errors.append(e)

    def lidar_callback() -> None:
        try:
            barrier.wait()
            for _ in range(100):
                stream.stats  # noqa: B018 - reads under the lock
                stream.notices()
                repr(stream)
        except BaseException as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=tracker), threading.Thread(target=lidar_callback)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert errors == []
    assert stream.stats["samples"] == 300
    # Frames come out in clock order, one per period.
    ts = [f.t_s for f in frames]
    assert ts == sorted(ts) and len(ts) == stream.stats["frames"]
    assert np.allclose(np.diff(ts), stream.period_s)


def test_internal_error_is_an_ordinary_exception() -> None:
    assert issubclass(gl.InternalError, RuntimeError)
    assert issubclass(gl.InternalError, Exception)
