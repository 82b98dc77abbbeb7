"""gaze_lidar.carla on synthetic buffers laid out exactly as CARLA's.

Layouts (LibCarla `LidarDetection`, `SemanticLidarDetection`, packed, little
endian): ray-cast x, y, z, intensity as float32 (16 bytes); semantic x, y,
z, cos_inc_angle as float32 then object_idx, object_tag as uint32 (24
bytes). The buffers below are built with `struct`, byte by byte, not with
the module's dtypes.
"""

from __future__ import annotations

import math
import struct
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest

import gaze_lidar as gl
from gaze_lidar import carla as glc

# (x, y, z) in CARLA's sensor frame (y right): azimuths 0, 90 (left), 180, 270.
POINTS = [(10.0, 0.0, 0.5), (0.0, -20.0, -1.0), (-30.0, 0.0, 0.0), (0.0, 150.0, 1.0)]


def ray_cast_bytes() -> bytes:
    return b"".join(struct.pack("<4f", x, y, z, 0.25 * i) for i, (x, y, z) in enumerate(POINTS))


def semantic_bytes() -> bytes:
    return b"".join(
        struct.pack("<4f2I", x, y, z, 0.5, 100 + i, 10 + i) for i, (x, y, z) in enumerate(POINTS)
    )


class LidarMeasurement:
    """Stands in for carla.LidarMeasurement: raw_data and len()."""

    def __init__(self, raw: bytes, per_point: int) -> None:
        self.raw_data = memoryview(raw)
        self._n = len(raw) // per_point

    def __len__(self) -> int:
        return self._n


class SemanticLidarMeasurement(LidarMeasurement):
    pass


class Measurement(LidarMeasurement):
    """A measurement whose type name says nothing: bytes per point decide."""


@dataclass
class Rotation:
    pitch: float = 0.0
    yaw: float = 0.0
    roll: float = 0.0


@dataclass
class Transform:
    rotation: Rotation = field(default_factory=Rotation)


class Attribute:
    def __init__(self, v: str) -> None:
        self.v = v

    def as_float(self) -> float:
        return float(self.v)


class Blueprint:
    """Stands in for carla.ActorBlueprint (string attributes, as CARLA keeps them)."""

    def __init__(self, **attrs: Any) -> None:
        self.attrs = {k: str(v) for k, v in attrs.items()}

    def has_attribute(self, name: str) -> bool:
        return name in self.attrs

    def get_attribute(self, name: str) -> Attribute:
        return Attribute(self.attrs[name])


def test_ray_cast_measurement_and_buffers() -> None:
    raw = ray_cast_bytes()
    for m in (LidarMeasurement(raw, 16), raw, memoryview(raw), bytearray(raw), Measurement(raw, 16)):
        pts = glc.points_from_measurement(m)
        assert pts.shape == (4, 4) and pts.dtype == np.float32
        np.testing.assert_array_equal(pts[:, :3], np.array(POINTS, dtype=np.float32))
        np.testing.assert_array_equal(pts[:, 3], [0.0, 0.25, 0.5, 0.75])
    np.testing.assert_allclose(gl.azimuth_deg(glc.points_from_measurement(raw)), [0, 90, 180, 270], atol=1e-12)
    with pytest.raises(ValueError, match="^measurement: a raw buffer of 16-byte points"):
        glc.points_from_measurement(raw[:-3])


def test_semantic_measurement() -> None:
    raw = semantic_bytes()
    for m in (SemanticLidarMeasurement(raw, 24), Measurement(raw, 24)):
        rec = glc.points_from_measurement(m)
        assert rec.dtype == glc.SEMANTIC_LIDAR_DTYPE and rec.shape == (4,)
        np.testing.assert_array_equal(rec["object_idx"], [100, 101, 102, 103])
        np.testing.assert_array_equal(rec["object_tag"], [10, 11, 12, 13])
        np.testing.assert_array_equal(rec["cos_inc_angle"], 0.5)
        np.testing.assert_allclose(gl.azimuth_deg(rec), [0, 90, 180, 270], atol=1e-12)
    rec = glc.points_from_measurement(raw, semantic=True)
    np.testing.assert_array_equal(rec["x"], [p[0] for p in POINTS])


def test_apply_to_measurement_with_the_sensors_yaw() -> None:
    p = gl.profile(mode="range", gaze_deg=90.0)  # driver looks left: less range there
    # Points at 80 m around the car; a sensor mounted straight sees azimuth = vehicle azimuth.
    az = np.arange(0.0, 360.0, 1.0) + 0.5
    pts = np.zeros((az.size, 4), dtype="<f4")
    pts[:, 0] = 80 * np.cos(np.radians(az))
    pts[:, 1] = -80 * np.sin(np.radians(az))
    m = LidarMeasurement(pts.tobytes(), 16)
    straight = glc.apply_to_measurement(p, m, rated_range_m=100.0)
    in_rof = (az > 60) & (az < 120)
    assert not straight[in_rof].any() and straight[~in_rof].all()
    # Mounted with CARLA yaw +90 (clockwise: facing right), the sensor's
    # azimuth β is the vehicle's β − 90: the region of focus moves by 90.
    turned = glc.apply_to_measurement(p, m, rated_range_m=100.0, sensor_transform=Transform(Rotation(yaw=90.0)))
    rof_in_sensor = (az > 150) & (az < 210)
    assert not turned[rof_in_sensor].any() and turned[~rof_in_sensor].all()
    np.testing.assert_array_equal(
        glc.apply_to_measurement(p, m, rated_range_m=100.0, sensor_carla_yaw_deg=90.0), turned
    )
    assert glc.sensor_yaw_deg(Transform(Rotation(yaw=30.0))) == -30.0


def test_blueprint_check_warns_about_frequency_dropoff_and_tick() -> None:
    p = gl.profile()  # 20 Hz
    good = Blueprint(rotation_frequency=20, dropoff_general_rate=0.0, dropoff_zero_intensity=0.0)
    assert glc.check_blueprint(good, p, fixed_delta_seconds=0.05) == []
    carla_defaults = Blueprint(rotation_frequency=10, dropoff_general_rate=0.45, dropoff_zero_intensity=0.4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        problems = glc.check_blueprint(carla_defaults, p, fixed_delta_seconds=0.05)
    assert [w.category for w in caught] == [glc.GazeLidarCarlaWarning] * 4
    assert problems[0].startswith("rotation_frequency: 10 Hz differs from the profile's frame rate 20 Hz")
    assert problems[1].startswith("dropoff_general_rate: 0.45 > 0")
    assert problems[2].startswith("dropoff_zero_intensity: 0.4 > 0")
    assert problems[3].startswith("fixed_delta_seconds: 0.05 s at 10 Hz is 0.5 turns per tick")
    # A dict works too; the semantic LiDAR has no drop-off attributes.
    assert glc.check_blueprint({"rotation_frequency": "20"}, p, warn=False) == []
    assert math.isclose(p.frame_rate_hz, 20.0)
