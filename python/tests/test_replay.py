"""`gaze-lidar replay` (issue 33) checked by a writer and a reader no one
here wrote: the fixture bag is written with the `mcap` + `mcap-ros2-support`
packages (real sensor_msgs/PointCloud2 and geometry_msgs/Vector3Stamped from
their ROS 2 message definitions), the binary replays it, and the output is
read back with the same packages and compared with `apply_profile`."""

from __future__ import annotations

import pathlib
import shutil
import subprocess
from typing import Any

import numpy as np
import pytest

import gaze_lidar as gl

mcap_writer = pytest.importorskip("mcap.writer")
mcap_reader = pytest.importorskip("mcap.reader")
ros2_writer = pytest.importorskip("mcap_ros2.writer")
ros2_decoder = pytest.importorskip("mcap_ros2.decoder")

GAZE, CLOUD, OTHER = "/dms/gaze", "/lidar/points", "/chatter"
T0 = 1_700_000_000_000_000_000

HEADER = "builtin_interfaces/Time stamp\nstring frame_id\n"
TIME = "int32 sec\nuint32 nanosec\n"
SEP = "=" * 80 + "\n"
VECTOR3_STAMPED = (
    "std_msgs/Header header\ngeometry_msgs/Vector3 vector\n"
    + SEP + "MSG: std_msgs/Header\n" + HEADER
    + SEP + "MSG: builtin_interfaces/Time\n" + TIME
    + SEP + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
)
POINT_CLOUD2 = (
    "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"
    + SEP + "MSG: std_msgs/Header\n" + HEADER
    + SEP + "MSG: builtin_interfaces/Time\n" + TIME
    + SEP + "MSG: sensor_msgs/PointField\n"
    "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\n"
    "uint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n"
)
POINT = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4")])


def stamp(t_ns: int) -> dict[str, int]:
    return {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}


def cloud_points(seed: int, n: int) -> np.ndarray[Any, Any]:
    rng = np.random.default_rng(seed)
    az = rng.uniform(0, 2 * np.pi, n)
    r = rng.uniform(1.0, 130.0, n)
    pts = np.zeros(n, dtype=POINT)
    pts["x"], pts["y"] = r * np.cos(az), r * np.sin(az)
    pts["z"] = rng.uniform(-0.5, 0.5, n)
    pts["intensity"] = 7.0
    return pts


def write_fixture(path: pathlib.Path) -> None:
    """Clouds at 10 Hz and gaze at 100 Hz (looking left) for 3 s, a 0.5 s
    gap in the gaze from 1.0 s, and an unrelated topic."""
    with open(path, "wb") as f:
        w = ros2_writer.Writer(f, compression=mcap_writer.CompressionType.LZ4)
        gaze_s = w.register_msgdef("geometry_msgs/msg/Vector3Stamped", VECTOR3_STAMPED)
        cloud_s = w.register_msgdef("sensor_msgs/msg/PointCloud2", POINT_CLOUD2)
        other_s = w.register_msgdef("std_msgs/msg/String", "string data\n")
        msgs: list[tuple[int, str, Any, dict[str, Any]]] = []
        for k in range(300):
            if 100 <= k < 150:
                continue
            t = T0 + k * 10_000_000
            msgs.append((t, GAZE, gaze_s, {
                "header": {"stamp": stamp(t), "frame_id": "base_link"},
                "vector": {"x": 0.0, "y": 1.0, "z": 0.0},
            }))
        for k in range(30):
            t = T0 + k * 100_000_000 + 3_000_000
            pts = cloud_points(k, 2000)
            msgs.append((t, CLOUD, cloud_s, {
                "header": {"stamp": stamp(t), "frame_id": "lidar"},
                "height": 1, "width": len(pts),
                "fields": [{"name": n, "offset": 4 * i, "datatype": 7, "count": 1}
                           for i, n in enumerate(("x", "y", "z", "intensity"))],
                "is_bigendian": False, "point_step": 16, "row_step": 16 * len(pts),
                "data": pts.tobytes(), "is_dense": True,
            }))
        for k in range(6):
            msgs.append((T0 + k * 500_000_000, OTHER, other_s, {"data": f"hello {k}"}))
        msgs.sort(key=lambda m: m[0])
        for seq, (t, topic, schema, msg) in enumerate(msgs):
            w.write_message(topic, schema, msg, log_time=t, publish_time=t, sequence=seq)
        w.finish()


def read(path: pathlib.Path) -> list[tuple[str, str, int, bytes, Any]]:
    """(topic, schema name, log_time, raw data, decoded or None) per message."""
    factory = ros2_decoder.DecoderFactory()
    out = []
    with open(path, "rb") as f:
        for schema, channel, message in mcap_reader.make_reader(f).iter_messages():
            decode = factory.decoder_for(channel.message_encoding, schema)
            decoded = decode(message.data) if decode is not None else None
            name = schema.name if schema is not None else ""
            out.append((channel.topic, name, message.log_time, bytes(message.data), decoded))
    return out


def cli(repo: pathlib.Path) -> pathlib.Path:
    path = repo / "target/release/gaze-lidar"
    if path.exists():
        return path
    found = shutil.which("gaze-lidar")
    if found is None:
        pytest.skip("the gaze-lidar binary is not built (cargo build --release)")
    return pathlib.Path(found)


def test_replay_of_an_independently_written_bag(repo: pathlib.Path, tmp_path: pathlib.Path) -> None:
    bag, out = tmp_path / "drive.mcap", tmp_path / "out.mcap"
    write_fixture(bag)
    subprocess.run(
        [str(cli(repo)), "replay", str(bag), "--gaze-topic", GAZE, "--cloud-topic", CLOUD,
         "--preset", "paper", "--mode", "range", "--out", str(out)],
        check=True, capture_output=True,
    )
    inp, got = read(bag), read(out)
    # Every input message, unchanged.
    key = sorted((m[0], m[2], m[3]) for m in inp)
    assert key == sorted((m[0], m[2], m[3]) for m in got if m[0] in (GAZE, CLOUD, OTHER))
    # The profiles: one per frame, each certified by `gaze-lidar check`,
    # fail-safe (no gaze) through the gap, adaptive (gaze left) before it.
    profiles = [(m[2], m[3].decode()) for m in got if m[0] == "/gaze_lidar/profile"]
    assert {m[1] for m in got if m[0] == "/gaze_lidar/profile"} == {"gaze_lidar.Profile"}
    assert {m[1] for m in got if m[0] == "/gaze_lidar/scene"} == {"foxglove.SceneUpdate"}
    assert len(profiles) >= 55
    for i, text in enumerate(sorted({p for _, p in profiles})):
        f = tmp_path / f"p{i}.json"
        f.write_text(text)
        subprocess.run([str(cli(repo)), "check", str(f)], check=True, capture_output=True)
    parsed = [(t, gl.Profile.from_json(p)) for t, p in profiles]

    def gaze(lo_s: float, hi_s: float) -> list[float | None]:
        return [p.gaze_deg for t, p in parsed if T0 + lo_s * 1e9 <= t < T0 + hi_s * 1e9]

    assert gaze(0.3, 0.95) and all(g is not None and abs(g - 90.0) < 1.0 for g in gaze(0.3, 0.95))
    assert gaze(1.15, 1.5) and all(g is None for g in gaze(1.15, 1.5))
    assert all(g is not None for g in gaze(1.8, 2.9))
    # One adapted cloud per input cloud, decoded by mcap-ros2-support: the
    # points apply_profile keeps, in order, with the profile of its frame.
    clouds = [m for m in inp if m[0] == CLOUD]
    adapted = [m for m in got if m[0] == CLOUD + "/adapted"]
    assert len(adapted) == len(clouds) == 30
    thinned = 0
    for k, (c, a) in enumerate(zip(clouds, adapted)):
        assert a[1] == "sensor_msgs/msg/PointCloud2" and a[2] == c[2]
        src = np.frombuffer(c[4].data, dtype=POINT)
        dst = np.frombuffer(a[4].data, dtype=POINT)
        assert a[4].width == len(dst) and a[4].point_step == 16
        profile = [p for t, p in parsed if t <= a[2]][-1]
        mask = gl.apply_profile(profile, src[["x", "y", "z"]], rated_range_m=100.0,
                                frame="iso8855", seed=k)
        np.testing.assert_array_equal(dst, src[mask])
        thinned += len(src) - len(dst)
    assert thinned > 0
