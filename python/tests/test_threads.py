"""GazeStream off the main thread (CARLA calls `sensor.listen` callbacks on
its own thread), and no Rust panic reaching Python as a BaseException."""

from __future__ import annotations

import queue
import threading
import time

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


def progress_during(call: object, repeat: int = 3) -> int:
    """How many times the main thread wakes up (0.5 ms naps) while a worker
    thread is inside `call()`: about zero if `call` holds the GIL."""
    inside = threading.Event()
    finished = threading.Event()

    def worker() -> None:
        for _ in range(repeat):
            inside.set()
            call()  # type: ignore[operator]
            inside.clear()
        finished.set()

    t = threading.Thread(target=worker)
    t.start()
    wakeups = 0
    while not finished.is_set():
        time.sleep(0.0005)
        if inside.is_set():
            wakeups += 1
    t.join()
    return wakeups


def test_the_gil_is_released_while_points_are_processed() -> None:
    p = gl.profile(mode="resolution", gaze_deg=90.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform(-100, 100, (2_000_000, 4)).astype(np.float32)  # no conversion: all native
    apply = progress_during(lambda: gl.apply_profile(p, pts, rated_range_m=100.0))
    azimuth = progress_during(lambda: gl.azimuth_deg(pts))
    # The probe can fail: a C loop that keeps the GIL (longer than
    # apply_profile here) lets the main thread wake only around the calls.
    held = progress_during(lambda: sum(range(20_000_000)))
    assert min(apply, azimuth) >= 50 and min(apply, azimuth) > 10 * held, (apply, azimuth, held)
