"""CARLA glue: measurements in, masks out, and a LiDAR blueprint check.

Pure Python; needs no ``carla`` install (it reads attributes, duck-typed).
The layouts are CARLA's documented ones (``LidarDetection`` and
``SemanticLidarDetection`` in LibCarla, read the same way by CARLA's own
PythonAPI examples with ``np.frombuffer``):

- ``sensor.lidar.ray_cast`` → ``carla.LidarMeasurement``: per point
  x, y, z, intensity, four float32 (16 bytes);
- ``sensor.lidar.ray_cast_semantic`` → ``carla.SemanticLidarMeasurement``:
  per point x, y, z, cos_inc_angle (float32), object_idx, object_tag
  (uint32) (24 bytes).

Coordinates are in the sensor's own frame, Unreal's axes (x forward, y
right, z up), metres: ``frame="carla"``. CARLA hands ``raw_data`` only for
the duration of the callback: the arrays returned here are views of it
unless ``copy=True``.

A CARLA ``Transform``'s rotation is in degrees with yaw positive clockwise
seen from above (towards +y, the right); the crate's azimuths are
counter-clockwise (ISO 8855), so a sensor mounted with ``yaw=θ`` has
``sensor_yaw_deg = -θ``. Pass the transform the sensor was attached with
(relative to the vehicle), not ``measurement.transform`` (the world pose).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any, Literal, Protocol, Union

import numpy as np
import numpy.typing as npt

from . import Profile, apply_profile
from ._points import RAY_CAST_POINT, raw_buffer

#: ``carla.LidarMeasurement.raw_data``: x, y, z, intensity (float32).
LIDAR_DTYPE = RAY_CAST_POINT
#: ``carla.SemanticLidarMeasurement.raw_data``: x, y, z, cos_inc_angle
#: (float32), object_idx, object_tag (uint32).
SEMANTIC_LIDAR_DTYPE = np.dtype(
    [
        ("x", "<f4"),
        ("y", "<f4"),
        ("z", "<f4"),
        ("cos_inc_angle", "<f4"),
        ("object_idx", "<u4"),
        ("object_tag", "<u4"),
    ]
)


class GazeLidarCarlaWarning(UserWarning):
    """A CARLA setting that makes the profile's effect on the cloud wrong."""


class _Rotation(Protocol):
    @property
    def yaw(self) -> float: ...


class _Transform(Protocol):
    @property
    def rotation(self) -> _Rotation: ...


Buffer = Union[bytes, bytearray, memoryview]


def _kind(measurement: Any, semantic: bool | None) -> bool:
    """Whether `measurement` is a semantic LiDAR measurement."""
    if semantic is not None:
        return semantic
    name = type(measurement).__name__
    if "Semantic" in name:
        return True
    if "Lidar" in name:
        return False
    # A LidarMeasurement-like object: bytes per detection decides.
    raw = getattr(measurement, "raw_data", None)
    if raw is not None:
        try:
            n = len(measurement)
        except TypeError:
            n = 0
        if n > 0:
            per_point = memoryview(raw).nbytes // n
            if per_point in (LIDAR_DTYPE.itemsize, SEMANTIC_LIDAR_DTYPE.itemsize):
                return per_point == SEMANTIC_LIDAR_DTYPE.itemsize
    return False


def points_from_measurement(
    measurement: Any, *, semantic: bool | None = None, copy: bool = False
) -> npt.NDArray[Any]:
    """The points of a CARLA LiDAR measurement as numpy.

    `measurement`: a ``carla.LidarMeasurement`` or
    ``carla.SemanticLidarMeasurement`` (anything with ``raw_data``), or the
    raw buffer itself (``bytes``, ``bytearray``, ``memoryview``). Ray-cast
    data comes back as an N×4 float32 array (x, y, z, intensity); semantic
    data as a structured array of :data:`SEMANTIC_LIDAR_DTYPE` (x, y, z,
    cos_inc_angle, object_idx, object_tag), which :func:`apply_profile`
    also takes. `semantic` forces the layout (default: from the
    measurement's type name, else from its bytes per detection, else
    ray-cast). Raises ValueError when the buffer is not a whole number of
    points.
    """
    raw = getattr(measurement, "raw_data", measurement)
    if not isinstance(raw, (bytes, bytearray, memoryview)):
        try:
            raw = memoryview(raw)
        except TypeError:
            raise ValueError(
                f"measurement: expected a CARLA LiDAR measurement or a byte buffer, got {type(measurement).__name__}"
            ) from None
    if _kind(measurement, semantic):
        rec = raw_buffer(raw, SEMANTIC_LIDAR_DTYPE, "measurement")
        return rec.copy() if copy else rec
    rec = raw_buffer(raw, LIDAR_DTYPE, "measurement")
    flat = rec.view("<f4").reshape(-1, 4)
    out = flat.astype(np.float32, copy=copy)
    return out


def sensor_yaw_deg(transform: _Transform | None = None, *, carla_yaw_deg: float | None = None) -> float:
    """The sensor's yaw in the crate's convention (degrees counter-clockwise,
    ISO 8855) from a CARLA transform (relative to the vehicle) or a CARLA
    yaw (degrees clockwise): its negative."""
    if transform is not None and carla_yaw_deg is not None:
        raise ValueError("sensor_transform: give a transform or a yaw, not both")
    if transform is not None:
        carla_yaw_deg = float(transform.rotation.yaw)
    return -float(carla_yaw_deg or 0.0)


def apply_to_measurement(
    profile: Profile,
    measurement: Any,
    *,
    rated_range_m: float,
    sensor_transform: _Transform | None = None,
    sensor_carla_yaw_deg: float | None = None,
    semantic: bool | None = None,
    model: Literal["physical", "argus"] = "physical",
    fog_mor_m: float | None = None,
    seed: int | None = 0,
    cloud_spin_rad_s: float | None = None,
) -> npt.NDArray[np.bool_]:
    """:func:`gaze_lidar.apply_profile` on a CARLA measurement: which of its
    points a sensor running `profile` would return (a bool mask, one entry
    per detection).

    The profile's azimuths are the vehicle's; give the sensor's mounting as
    `sensor_transform` (the ``carla.Transform`` it was attached with,
    relative to the vehicle) or `sensor_carla_yaw_deg` (CARLA's clockwise
    yaw). Only the yaw is used: a LiDAR spins about its own z axis.
    """
    pts = points_from_measurement(measurement, semantic=semantic)
    yaw = sensor_yaw_deg(sensor_transform, carla_yaw_deg=sensor_carla_yaw_deg)
    return apply_profile(
        profile,
        pts,
        rated_range_m=rated_range_m,
        model=model,
        fog_mor_m=fog_mor_m,
        seed=seed,
        frame="carla",
        cloud_spin_rad_s=cloud_spin_rad_s,
        sensor_yaw_deg=yaw,
    )


#: CARLA's random drop-off attributes of ``sensor.lidar.ray_cast`` (the
#: semantic LiDAR has none): the general rate thins every cloud at random,
#: the zero-intensity one drops points whose intensity is below the limit.
DROPOFF_ATTRIBUTES = ("dropoff_general_rate", "dropoff_zero_intensity")


def _attribute(blueprint: Any, name: str) -> float | None:
    if isinstance(blueprint, Mapping):
        v = blueprint.get(name)
        return None if v is None else float(v)
    has = getattr(blueprint, "has_attribute", None)
    if has is not None and not has(name):
        return None
    attr = blueprint.get_attribute(name)
    as_float = getattr(attr, "as_float", None)
    return float(as_float()) if as_float is not None else float(str(attr))


#: CARLA's default ``range`` of ``sensor.lidar.ray_cast``, m.
CARLA_DEFAULT_RANGE_M = 10.0


def profile_range_m(profile: Profile, rated_range_m: float | None = None) -> float | None:
    """The farthest a sensor running `profile` sees, m: the largest per-bin
    range of ``profile.figures`` (range on the reference reflectivity in
    clear air, MOR 20 km) and `rated_range_m` (the uniform baseline's), the
    larger of those known; None when neither is."""
    known: list[float] = [] if rated_range_m is None else [float(rated_range_m)]
    figures = profile.figures
    if figures is not None:
        for region in figures["profile"].values():
            if region is not None:
                known.append(float(region["range_m"]["max"]))
    return max(known) if known else None


def check_blueprint(
    blueprint: Any,
    profile: Profile,
    *,
    fixed_delta_seconds: float | None = None,
    rated_range_m: float | None = None,
    warn: bool = True,
) -> list[str]:
    """Checks a CARLA LiDAR blueprint against `profile`; returns one line per
    problem (and, with `warn`, issues each as a :class:`GazeLidarCarlaWarning`).

    `blueprint`: a ``carla.ActorBlueprint`` (``has_attribute`` /
    ``get_attribute(...).as_float()``) or a dict of attribute values.
    Problems: ``rotation_frequency`` differs from the profile's
    ``frame_rate_hz`` (the density thinning is relative to the spin the
    cloud was recorded at, and one measurement is not one profile frame);
    CARLA's own drop-off (``dropoff_general_rate``,
    ``dropoff_zero_intensity``) already thins the cloud at random, on top
    of the profile; with `fixed_delta_seconds` (synchronous mode), a tick
    that is not one whole turn (each measurement then holds a partial or a
    repeated sweep); ``range`` (CARLA's default: 10 m) shorter than the
    farthest the profile sees (:func:`profile_range_m`: its figures' largest
    per-bin range, at least the sensor's rated range; `rated_range_m` gives
    the rated range for a profile whose preset is unknown), so CARLA drops
    the far points the profile's range control is about.
    """
    problems: list[str] = []
    hz = _attribute(blueprint, "rotation_frequency")
    if hz is not None and not math.isclose(hz, profile.frame_rate_hz, rel_tol=1e-6):
        problems.append(
            f"rotation_frequency: {hz:g} Hz differs from the profile's frame rate "
            f"{profile.frame_rate_hz:g} Hz: set it to {profile.frame_rate_hz:g} "
            "(or pass cloud_spin_rad_s = 2π·rotation_frequency)"
        )
    for name in DROPOFF_ATTRIBUTES:
        rate = _attribute(blueprint, name)
        if rate is not None and rate > 0.0:
            problems.append(
                f"{name}: {rate:g} > 0: CARLA already drops points at random, on top of the "
                f"profile's thinning; set it to 0"
            )
    sensor_range = _attribute(blueprint, "range")
    needed = profile_range_m(profile, rated_range_m)
    if sensor_range is not None and needed is not None and sensor_range < needed:
        default = " (CARLA's default)" if sensor_range == CARLA_DEFAULT_RANGE_M else ""
        problems.append(
            f"range: {sensor_range:g} m{default} is shorter than the {needed:.4g} m the profile "
            f"reaches (rated range on the reference reflectivity in clear air, more where "
            f"range control raises the power): CARLA drops every point beyond it; set range "
            f"to at least {math.ceil(needed):d}"
        )
    if fixed_delta_seconds is not None and hz is not None and hz > 0:
        turns = fixed_delta_seconds * hz
        if not math.isclose(turns, 1.0, rel_tol=1e-6):
            problems.append(
                f"fixed_delta_seconds: {fixed_delta_seconds:g} s at {hz:g} Hz is {turns:g} turns "
                f"per tick: each measurement holds {'part of a' if turns < 1 else 'more than one'} "
                f"sweep; use fixed_delta_seconds = {1.0 / hz:g}"
            )
    if warn:
        for p in problems:
            warnings.warn(p, GazeLidarCarlaWarning, stacklevel=2)
    return problems


__all__ = [
    "CARLA_DEFAULT_RANGE_M",
    "DROPOFF_ATTRIBUTES",
    "LIDAR_DTYPE",
    "SEMANTIC_LIDAR_DTYPE",
    "Buffer",
    "GazeLidarCarlaWarning",
    "apply_to_measurement",
    "check_blueprint",
    "points_from_measurement",
    "profile_range_m",
    "sensor_yaw_deg",
]
