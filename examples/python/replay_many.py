"""Replays many recorded drives (ROS 2 bags, MCAP) through gaze_lidar.replay
at once: with threads (the replay releases the GIL), with processes
(concurrent.futures), or across a dask.distributed cluster when dask is
installed (a fleet's recordings outgrow one machine).

Each bag is replayed by the same Rust code as `gaze-lidar replay`, on its
own and deterministically: the outputs are byte-identical to replaying the
bags one by one, however many workers run and in whatever order they
finish (python/tests/test_replay.py checks it).

    python examples/python/replay_many.py OUT_DIR BAG.mcap... \\
        --gaze-topic /dms/gaze --cloud-topic /lidar/points \\
        [--executor threads|processes|dask|serial] [--workers N] [--scheduler ADDRESS]

OUT_DIR/NAME.mcap is written for each input BAG .../NAME.mcap (the names
must differ). With --executor dask and no --scheduler, a local cluster is
started; with --scheduler, the bags' paths must be readable by the workers
(a shared file system).
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import multiprocessing
import os
import pathlib
import sys
from collections.abc import Sequence
from typing import Any

import gaze_lidar as gl

def _targets(bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str) -> list[tuple[str, str]]:
    out = pathlib.Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    pairs = [(str(b), str(out / pathlib.Path(b).name)) for b in bags]
    names = [o for _, o in pairs]
    if len(set(names)) != len(names):
        raise ValueError("bags: two inputs have the same file name (their outputs would collide)")
    return pairs


def replay_one(bag: str, out: str, options: dict[str, Any]) -> dict[str, int]:
    """One bag (a top-level function: processes and dask workers pickle it)."""
    return gl.replay(bag, out, **options)


def replay_serial(
    bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str, **options: Any
) -> dict[str, dict[str, int]]:
    """The reference: one bag after another, in this process."""
    return {b: replay_one(b, o, options) for b, o in _targets(bags, out_dir)}


def _pool(
    pool: cf.Executor, bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str,
    options: dict[str, Any],
) -> dict[str, dict[str, int]]:
    with pool:
        futures = {b: pool.submit(replay_one, b, o, options) for b, o in _targets(bags, out_dir)}
        return {b: f.result() for b, f in futures.items()}


def replay_threads(
    bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str, workers: int = 4,
    **options: Any,
) -> dict[str, dict[str, int]]:
    """A thread pool: the replay runs without the GIL, so threads use the cores."""
    return _pool(cf.ThreadPoolExecutor(max_workers=workers), bags, out_dir, options)


def replay_processes(
    bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str, workers: int = 4,
    **options: Any,
) -> dict[str, dict[str, int]]:
    """A process pool (spawned workers: nothing inherited from this process)."""
    ctx = multiprocessing.get_context("spawn")
    return _pool(cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx), bags, out_dir, options)


def dask_available() -> bool:
    """Whether dask.distributed can be imported."""
    try:
        import dask.distributed  # type: ignore[import-not-found,import-untyped,unused-ignore]  # noqa: F401
    except ImportError:
        return False
    return True


def replay_dask(
    bags: Sequence[os.PathLike[str] | str], out_dir: os.PathLike[str] | str, workers: int = 4,
    scheduler: str | None = None, **options: Any,
) -> dict[str, dict[str, int]]:
    """dask.distributed: a local cluster of `workers` single-threaded worker
    processes, or the cluster at `scheduler`."""
    import dask.distributed  # type: ignore[import-not-found,import-untyped,unused-ignore]

    # Untyped in places: used through Any.
    dist: Any = dask.distributed

    pairs = _targets(bags, out_dir)
    if scheduler is None:
        cluster = dist.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = dist.Client(cluster)
    else:
        cluster, client = None, dist.Client(scheduler)
    try:
        # pure=False: each call writes a file, never served from a cache.
        futures = [client.submit(replay_one, b, o, options, pure=False) for b, o in pairs]
        results: list[dict[str, int]] = client.gather(futures)
        return {b: r for (b, _), r in zip(pairs, results)}
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("bags", nargs="+")
    ap.add_argument("--gaze-topic", required=True)
    ap.add_argument("--cloud-topic", required=True)
    ap.add_argument("--preset", default="paper")
    ap.add_argument("--mode", default="range")
    ap.add_argument("--executor", choices=["threads", "processes", "dask", "serial"], default="threads")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--scheduler", help="a dask.distributed scheduler address (with --executor dask)")
    a = ap.parse_args(argv)
    options = {"gaze_topic": a.gaze_topic, "cloud_topic": a.cloud_topic, "preset": a.preset,
               "mode": a.mode}
    if a.executor == "serial":
        stats = replay_serial(a.bags, a.out_dir, **options)
    elif a.executor == "threads":
        stats = replay_threads(a.bags, a.out_dir, a.workers, **options)
    elif a.executor == "processes":
        stats = replay_processes(a.bags, a.out_dir, a.workers, **options)
    else:
        if not dask_available():
            print("dask.distributed is not installed (pip install 'dask[distributed]')", file=sys.stderr)
            return 2
        stats = replay_dask(a.bags, a.out_dir, a.workers, a.scheduler, **options)
    for bag, s in stats.items():
        print(f"{bag}: {s['clouds']} clouds, {s['points_kept']} of {s['points_in']} points kept, "
              f"{s['frames']} frames ({s['fail_safe_frames']} fail-safe)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
