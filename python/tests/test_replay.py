"""`gaze-lidar replay` checked by a writer and a reader no one
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


TF_MESSAGE = (
    "geometry_msgs/TransformStamped[] transforms\n"
    + SEP + "MSG: geometry_msgs/TransformStamped\n"
    "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"
    + SEP + "MSG: std_msgs/Header\n" + HEADER
    + SEP + "MSG: builtin_interfaces/Time\n" + TIME
    + SEP + "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n"
    + SEP + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
    + SEP + "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"
)


def yaw_quaternion(yaw_deg: float, roll_deg: float = 0.0) -> dict[str, float]:
    """The rotation Rz(yaw)·Rx(roll) as a geometry_msgs/Quaternion."""
    h, r = np.radians(yaw_deg) / 2, np.radians(roll_deg) / 2
    # (0, 0, sin h, cos h) ⊗ (sin r, 0, 0, cos r)
    return {"x": float(np.cos(h) * np.sin(r)), "y": float(np.sin(h) * np.sin(r)),
            "z": float(np.sin(h) * np.cos(r)), "w": float(np.cos(h) * np.cos(r))}


def write_fixture(path: pathlib.Path, compression: str = "LZ4",
                  mount: dict[str, float] | None = None) -> None:
    """Clouds at 10 Hz and gaze at 100 Hz (looking left) for 3 s, a 0.5 s
    gap in the gaze from 1.0 s, and an unrelated topic; with `mount`, a
    /tf_static message from base_link to the cloud frame "lidar"."""
    with open(path, "wb") as f:
        w = ros2_writer.Writer(f, compression=getattr(mcap_writer.CompressionType, compression))
        gaze_s = w.register_msgdef("geometry_msgs/msg/Vector3Stamped", VECTOR3_STAMPED)
        cloud_s = w.register_msgdef("sensor_msgs/msg/PointCloud2", POINT_CLOUD2)
        other_s = w.register_msgdef("std_msgs/msg/String", "string data\n")
        msgs: list[tuple[int, str, Any, dict[str, Any]]] = []
        if mount is not None:
            tf_s = w.register_msgdef("tf2_msgs/msg/TFMessage", TF_MESSAGE)
            msgs.append((T0, "/tf_static", tf_s, {"transforms": [{
                "header": {"stamp": stamp(T0), "frame_id": "base_link"},
                "child_frame_id": "lidar",
                "transform": {"translation": {"x": 1.2, "y": 0.0, "z": 1.9}, "rotation": mount},
            }]}))
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


@pytest.mark.parametrize("compression", ["LZ4", "ZSTD", "NONE"])
def test_replay_of_an_independently_written_bag(
    repo: pathlib.Path, tmp_path: pathlib.Path, compression: str
) -> None:
    if compression == "ZSTD":
        pytest.importorskip("zstandard")
    bag, out = tmp_path / "drive.mcap", tmp_path / "out.mcap"
    write_fixture(bag, compression)
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
    profiles = [(m[2], m[4].data) for m in got if m[0] == "/gaze_lidar/profile"]
    assert {m[1] for m in got if m[0] == "/gaze_lidar/profile"} == {"std_msgs/msg/String"}
    scenes = [m[4] for m in got if m[0] == "/gaze_lidar/scene"]
    assert {m[1] for m in got if m[0] == "/gaze_lidar/scene"} == {
        "visualization_msgs/msg/MarkerArray"}
    assert len(scenes) == len(profiles)
    assert all([mk.type for mk in s.markers] == [11, 9] and len(s.markers[0].points) > 0
               for s in scenes)
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


def adapted_vs_rule(inp: list[Any], got: list[Any], sensor_yaw_deg: float) -> int:
    """Checks each adapted cloud against apply_profile on its input cloud
    (the sensor turned by sensor_yaw_deg); returns the adaptive clouds."""
    parsed = [(m[2], gl.Profile.from_json(m[4].data)) for m in got
              if m[0] == "/gaze_lidar/profile"]
    clouds = [m for m in inp if m[0] == CLOUD]
    adapted = [m for m in got if m[0] == CLOUD + "/adapted"]
    assert len(adapted) == len(clouds) == 30
    adaptive = 0
    for k, (c, a) in enumerate(zip(clouds, adapted)):
        src = np.frombuffer(c[4].data, dtype=POINT)
        dst = np.frombuffer(a[4].data, dtype=POINT)
        profile = [p for t, p in parsed if t <= a[2]][-1]
        adaptive += profile.gaze_deg is not None
        mask = gl.apply_profile(profile, src[["x", "y", "z"]], rated_range_m=100.0,
                                frame="iso8855", seed=k, sensor_yaw_deg=sensor_yaw_deg)
        np.testing.assert_array_equal(dst, src[mask])
    return adaptive


def test_the_mounting_yaw_is_read_from_tf_static(tmp_path: pathlib.Path) -> None:
    """A /tf_static transform base_link → lidar (a 75° yaw and a 1° roll
    about the lidar's own x axis) written by mcap-ros2-support: the clouds
    are turned by 75° before the rule; sensor_yaw_deg overrides it; a 20°
    roll is refused by name."""
    bag = tmp_path / "tf.mcap"
    write_fixture(bag, "NONE", mount=yaw_quaternion(75.0, roll_deg=1.0))
    out = tmp_path / "out.mcap"
    stats = gl.replay(bag, out, gaze_topic=GAZE, cloud_topic=CLOUD)
    assert stats["transforms"] == 1 and stats["clouds_without_tf"] == 0
    assert adapted_vs_rule(read(bag), read(out), 75.0) >= 10
    gl.replay(bag, out, gaze_topic=GAZE, cloud_topic=CLOUD, sensor_yaw_deg=-10.0)
    assert adapted_vs_rule(read(bag), read(out), -10.0) >= 10
    stats = gl.replay(bag, out, gaze_topic=GAZE, cloud_topic=CLOUD, vehicle_frame="odom")
    assert stats["clouds_without_tf"] == 30
    assert adapted_vs_rule(read(bag), read(out), 0.0) >= 10
    write_fixture(bag, "NONE", mount=yaw_quaternion(75.0, roll_deg=20.0))
    out.unlink()
    with pytest.raises(ValueError, match=r"/tf_static: .*\"lidar\".*20\.000°"):
        gl.replay(bag, out, gaze_topic=GAZE, cloud_topic=CLOUD)
    assert not out.exists()


def test_the_binding_writes_what_the_cli_writes(repo: pathlib.Path, tmp_path: pathlib.Path) -> None:
    bag = tmp_path / "drive.mcap"
    write_fixture(bag)
    cases: list[tuple[list[str], dict[str, Any]]] = [
        ([], {}),
        (["--compression", "zstd", "--seed", "9", "--mode", "joint", "--sensor-yaw-deg", "30"],
         {"compression": "zstd", "seed": 9, "mode": "joint", "sensor_yaw_deg": 30.0}),
    ]
    for extra_cli, extra_py in cases:
        a, b = tmp_path / "cli.mcap", tmp_path / "py.mcap"
        subprocess.run(
            [str(cli(repo)), "replay", str(bag), "--gaze-topic", GAZE, "--cloud-topic", CLOUD,
             "--out", str(a), *extra_cli],
            check=True, capture_output=True,
        )
        stats = gl.replay(str(bag), b, gaze_topic=GAZE, cloud_topic=CLOUD, **extra_py)
        assert a.read_bytes() == b.read_bytes()
        assert stats["clouds"] == 30 and stats["messages"] == len(read(bag))
    with pytest.raises(ValueError, match="compression"):
        gl.replay(bag, tmp_path / "x.mcap", gaze_topic=GAZE, cloud_topic=CLOUD,
                  compression="gzip")  # type: ignore[arg-type]
    (tmp_path / "cut.mcap").write_bytes(bag.read_bytes()[:5000])
    with pytest.raises(ValueError, match=r"at byte \d+: .*truncated after 5000 bytes"):
        gl.replay(tmp_path / "cut.mcap", tmp_path / "x.mcap", gaze_topic=GAZE, cloud_topic=CLOUD)
    assert not (tmp_path / "x.mcap").exists()


def test_many_bags_in_parallel_are_byte_identical_to_one_by_one(
    repo: pathlib.Path, tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """examples/python/replay_many.py: threads, processes and (when
    installed) dask.distributed give the files replaying each bag alone
    gives."""
    import importlib

    # Importable by name: spawned worker processes import it again.
    monkeypatch.syspath_prepend(str(repo / "examples/python"))
    ex = importlib.import_module("replay_many")
    bags = []
    for i, c in enumerate(["LZ4", "NONE", "LZ4", "NONE"]):
        bags.append(tmp_path / f"drive{i}.mcap")
        write_fixture(bags[-1], c, mount=yaw_quaternion(30.0 * i) if i % 2 else None)
    options = {"gaze_topic": GAZE, "cloud_topic": CLOUD, "preset": "paper", "mode": "range"}
    serial = tmp_path / "serial"
    ex.replay_serial(bags, serial, **options)
    want = {p.name: p.read_bytes() for p in serial.iterdir()}
    assert len(want) == len(bags)
    runs = {"threads": ex.replay_threads, "processes": ex.replay_processes}
    if ex.dask_available():
        runs["dask"] = ex.replay_dask
    for name, run in runs.items():
        out = tmp_path / name
        stats = run(bags, out, workers=2, **options)
        assert sorted(stats) == sorted(str(b) for b in bags)
        assert {p.name: p.read_bytes() for p in out.iterdir()} == want, name


def test_the_binding_checks_options_by_keyword_before_reading(tmp_path: pathlib.Path) -> None:
    cut = tmp_path / "cut.mcap"
    write_fixture(cut)
    cut.write_bytes(cut.read_bytes()[:5000])
    out = tmp_path / "x.mcap"
    cases: list[tuple[str, Any]] = [
        ("fog_mor_m", 5e-324), ("cloud_spin_rad_s", 5e-324), ("sensor_yaw_deg", 5e-324),
        ("rated_range_m", 5e-324), ("max_mount_tilt_deg", 5e-324),
        ("reorder_window_ms", 5e-324), ("cloud_spin_rad_s", 0.0), ("fog_mor_m", -1.0),
        ("bins", 36000), ("scene_topic", "/gaze_lidar/profile"), ("adapted_topic", GAZE),
    ]
    for key, value in cases:
        with pytest.raises(ValueError, match=rf"^{key}: "):
            gl.replay(cut, out, gaze_topic=GAZE, cloud_topic=CLOUD, **{key: value})
    with pytest.raises(ValueError, match=r"^out_path: "):
        gl.replay(cut, tmp_path / "no" / "such" / "x.mcap", gaze_topic=GAZE, cloud_topic=CLOUD)
    assert not out.exists()


def test_attachments_metadata_and_sequences_of_an_independent_bag_are_copied(
        tmp_path: pathlib.Path) -> None:
    bag, out = tmp_path / "drive.mcap", tmp_path / "out.mcap"
    write_fixture(bag)
    # The same messages rewritten with an attachment and a metadata record,
    # by the independent writer.
    rich = tmp_path / "rich.mcap"
    with open(bag, "rb") as f, open(rich, "wb") as g:
        reader = mcap_reader.make_reader(f)
        w = mcap_writer.Writer(g)
        w.start(profile="ros2", library="test")
        w.add_attachment(create_time=T0, log_time=T0, name="calibration.yaml",
                         media_type="application/yaml", data=b"lidar: {yaw: 0}\n")
        w.add_metadata(name="rosbag2", data={"vehicle": "car 7"})
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        sequences: list[tuple[str, int, int]] = []
        for schema, channel, message in reader.iter_messages():
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = w.register_schema(schema.name, schema.encoding, schema.data)
            if channel.id not in channels:
                channels[channel.id] = w.register_channel(
                    channel.topic, channel.message_encoding,
                    schemas.get(channel.schema_id, 0), channel.metadata)
            seq = 1000 + 3 * len(sequences)
            sequences.append((channel.topic, message.log_time, seq))
            w.add_message(channels[channel.id], message.log_time, message.data,
                          message.publish_time, seq)
        w.finish()
    stats = gl.replay(rich, out, gaze_topic=GAZE, cloud_topic=CLOUD)
    assert stats["attachments"] == 1 and stats["metadata"] == 1
    with open(out, "rb") as f:
        reader = mcap_reader.make_reader(f)
        attachments = list(reader.iter_attachments())
        metadata = list(reader.iter_metadata())
        got = sorted((c.topic, m.log_time, m.sequence) for _, c, m in reader.iter_messages()
                     if c.topic in (GAZE, CLOUD, OTHER))
    assert [(a.name, a.media_type, a.data) for a in attachments] == [
        ("calibration.yaml", "application/yaml", b"lidar: {yaw: 0}\n")]
    assert [(m.name, m.metadata) for m in metadata] == [("rosbag2", {"vehicle": "car 7"})]
    assert got == sorted(sequences)


def test_rosbags_anyreader_reads_every_message_of_the_output(
    repo: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    """Every output channel (copied, adapted, profile, picture) is ros2msg +
    CDR: the rosbags package (an independent reader) opens the file and
    decodes every message; the profiles are profile@1 documents."""
    anyreader = pytest.importorskip("rosbags.highlevel")
    bag, out = tmp_path / "drive.mcap", tmp_path / "out.mcap"
    write_fixture(bag, "NONE", mount=yaw_quaternion(30.0))
    subprocess.run(
        [str(cli(repo)), "replay", str(bag), "--gaze-topic", GAZE, "--cloud-topic", CLOUD,
         "--out", str(out)],
        check=True, capture_output=True,
    )
    want = read(out)
    got: list[tuple[str, int]] = []
    profiles = 0
    frames: set[str] = set()
    with anyreader.AnyReader([out]) as reader:
        for connection, t, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            got.append((connection.topic, t))
            if connection.topic == "/gaze_lidar/profile":
                assert gl.Profile.from_json(msg.data).frame_rate_hz > 0
                profiles += 1
            if connection.topic == "/gaze_lidar/scene":
                assert [m.type for m in msg.markers] == [11, 9]
                # The cloud's frame (the vehicle's before the first cloud).
                frames.add(msg.markers[0].header.frame_id)
            if connection.topic == CLOUD + "/adapted":
                assert msg.point_step == 16 and len(msg.data) == 16 * msg.width
    assert profiles >= 55
    assert frames == {"base_link", "lidar"}
    assert sorted(got) == sorted((m[0], m[2]) for m in want)
