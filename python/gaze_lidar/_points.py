"""Point clouds in, one layout out: what the native layer reads.

The native functions read only a C-contiguous N×3 or N×4 float32/float64
array in native byte order (anything else is refused there, never
misread). :func:`as_points` brings every input numpy can view as real
numbers to that layout, by numpy's own conversion rules
(``np.ascontiguousarray(a, dtype=...)``: values are converted, never
reinterpreted), so memory order, strides, byte order and dtype cannot
change the answer:

- any 2-D array-like with 3 or 4 columns (x, y, z[, intensity]): numpy
  arrays of any real dtype (float16/32/64/longdouble, signed and unsigned
  integers), either byte order, C or Fortran order, strided or column
  views, nested lists; float32 stays float32 (CARLA's dtype: no copy when
  already C-contiguous), every other dtype becomes float64 (longdouble is
  rounded to float64);
- an empty input (``[]``, shape (0,), (0, 3), (0, 4)): an empty cloud;
- a structured array with fields ``x``, ``y``, ``z`` (CARLA's semantic
  LiDAR dtype, see :mod:`gaze_lidar.carla`): those fields, as float64;
- ``bytes``, ``bytearray`` or a byte ``memoryview`` (e.g. a CARLA
  ``LidarMeasurement.raw_data``): CARLA's ray-cast layout, little-endian
  float32 x, y, z, intensity per 16-byte point.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

#: CARLA's ``sensor.lidar.ray_cast`` point: x, y, z, intensity (float32).
RAY_CAST_POINT = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4")])


def raw_buffer(buf: Any, dtype: np.dtype[Any], name: str = "points") -> npt.NDArray[Any]:
    """A read-only structured view of a raw byte buffer of `dtype` records."""
    nbytes = memoryview(buf).nbytes
    if nbytes % dtype.itemsize:
        raise ValueError(
            f"{name}: a raw buffer of {dtype.itemsize}-byte points must hold a multiple of "
            f"{dtype.itemsize} bytes, got {nbytes}"
        )
    return np.frombuffer(buf, dtype=dtype)


def _is_byte_buffer(points: Any) -> bool:
    if isinstance(points, (bytes, bytearray)):
        return True
    return isinstance(points, memoryview) and points.ndim <= 1 and points.format in ("B", "b", "c")


def as_points(points: Any, name: str = "points") -> npt.NDArray[np.float32] | npt.NDArray[np.float64]:
    """`points` as a C-contiguous N×3 or N×4 float32/float64 array (see the
    module docs); raises ValueError naming `name` for anything else."""
    if _is_byte_buffer(points):
        a: npt.NDArray[Any] = raw_buffer(points, RAY_CAST_POINT, name)
    else:
        try:
            a = np.asarray(points)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{name}: not an array of numbers ({e})") from None
    if a.dtype.names is not None:
        missing = [f for f in ("x", "y", "z") if f not in a.dtype.names]
        if missing:
            raise ValueError(
                f"{name}: a structured array needs fields x, y, z; it has {', '.join(a.dtype.names)}"
            )
        flat = a.reshape(-1)
        cols = []
        for f in ("x", "y", "z"):
            c = flat[f]
            if c.ndim != 1 or c.dtype.kind not in "fiu":
                raise ValueError(f"{name}: field {f} has dtype {c.dtype}, not a real scalar")
            cols.append(np.asarray(c, dtype=np.float64))
        return np.ascontiguousarray(np.stack(cols, axis=-1).reshape(-1, 3), dtype=np.float64)
    if a.size == 0 and a.ndim <= 1:
        return np.empty((0, 3), dtype=np.float64)
    if a.ndim != 2 or a.shape[1] not in (3, 4):
        raise ValueError(
            f"{name}: expected an N×3 or N×4 array (x, y, z[, intensity]), got shape {a.shape}"
        )
    if a.dtype.kind not in "fiu":
        raise ValueError(f"{name}: dtype {a.dtype} is not a real number type")
    if a.dtype.kind == "f" and a.dtype.itemsize == 4:
        return np.ascontiguousarray(a, dtype=np.float32)
    return np.ascontiguousarray(a, dtype=np.float64)


def rotate_yaw(
    points: npt.NDArray[np.float32] | npt.NDArray[np.float64], frame: str, sensor_yaw_deg: float
) -> npt.NDArray[np.float64]:
    """x, y, z of `points` (in `frame`, the sensor's axes) in the vehicle's
    ISO 8855 axes, for a sensor whose x axis points `sensor_yaw_deg` degrees
    counter-clockwise (ISO 8855, to the left) of the vehicle's: an azimuth
    β in the sensor frame is β + yaw in the vehicle frame."""
    if frame not in ("carla", "iso8855"):
        raise ValueError(f"frame: '{frame}' is not one of carla, iso8855")
    yaw = float(sensor_yaw_deg)
    if not np.isfinite(yaw):
        raise ValueError(f"sensor_yaw_deg: {yaw} is not a finite angle")
    x = points[:, 0].astype(np.float64)
    y_left = points[:, 1].astype(np.float64)
    if frame == "carla":
        y_left = -y_left
    c, s = np.cos(np.radians(yaw)), np.sin(np.radians(yaw))
    out = np.empty((points.shape[0], 3), dtype=np.float64)
    out[:, 0] = c * x - s * y_left
    out[:, 1] = s * x + c * y_left
    out[:, 2] = points[:, 2]
    return out
