"""Every layout numpy can hand over reads as the same points.

Guards against a regression: a Fortran-ordered array passed the native
layer's contiguity test and was read row-major (`azimuth_deg` gave
[0, 90, 0, 315] for points at [0, 90, 180, 270]).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest

import gaze_lidar as gl
from gaze_lidar._points import as_points

# CARLA frame (y right): azimuths 0, 90, 180, 270 degrees.
QUAD = np.array([[10, 0, 0, 1], [0, -10, 0, 1], [-10, 0, 0, 1], [0, 10, 0, 1]], dtype=np.float64)


def sweep(n: int = 5000, seed: int = 3) -> npt.NDArray[np.float32]:
    rng = np.random.default_rng(seed)
    az = np.radians(rng.uniform(0, 360, n))
    r = rng.uniform(1, 180, n)
    pts = np.empty((n, 4), dtype=np.float32)
    pts[:, 0] = r * np.cos(az)
    pts[:, 1] = -r * np.sin(az)
    pts[:, 2] = rng.uniform(-2, 2, n)
    pts[:, 3] = rng.uniform(0, 1, n)
    return pts


def test_fortran_order_regression() -> None:
    for dtype in (np.float32, np.float64):
        q = QUAD.astype(dtype)
        f = np.asfortranarray(q)
        assert f.flags.f_contiguous and not f.flags.c_contiguous
        np.testing.assert_allclose(gl.azimuth_deg(f), [0, 90, 180, 270], atol=1e-12)
        np.testing.assert_array_equal(gl.azimuth_deg(f), gl.azimuth_deg(q))
    p = gl.profile(mode="range", gaze_deg=90.0)
    pts = sweep()
    want = gl.apply_profile(p, pts, rated_range_m=100.0)
    assert 0 < want.sum() < len(want)
    for layout in (np.asfortranarray(pts), np.asfortranarray(pts.astype(np.float64)), pts.T.copy().T):
        np.testing.assert_array_equal(gl.apply_profile(p, layout, rated_range_m=100.0), want)


def test_the_native_layer_refuses_what_it_would_misread() -> None:
    from gaze_lidar import _native

    f = np.asfortranarray(QUAD.astype(np.float32))
    with pytest.raises(ValueError, match="^points: the native layer takes a C-contiguous"):
        _native.azimuth_deg(f)
    with pytest.raises(ValueError, match="^points: "):
        _native.azimuth_deg(QUAD[::2])
    with pytest.raises(ValueError, match="^points: "):
        _native.azimuth_deg(QUAD.astype(">f8"))


@pytest.mark.parametrize(
    "make",
    [
        lambda q: q.tolist(),
        lambda q: [tuple(r) for r in q.tolist()],
        lambda q: q.astype(">f4"),
        lambda q: q.astype(">f8"),
        lambda q: q.astype(np.float16),
        lambda q: q.astype(np.longdouble),
        lambda q: q.astype(np.int16),
        lambda q: q.astype(np.int64),
        lambda q: q.astype(">i4"),
        lambda q: np.abs(q).astype(np.uint8) * np.sign(q).astype(np.int8),
        lambda q: q[:, :3],
        lambda q: np.repeat(q, 3, axis=0)[::3],
        lambda q: np.repeat(q, 2, axis=1)[:, ::2],
        lambda q: np.ascontiguousarray(q[::-1])[::-1],
        lambda q: q.T.copy().T,
        lambda q: memoryview(q.astype(np.float64)),
    ],
)
def test_layouts_read_as_the_same_points(make: object) -> None:
    got = gl.azimuth_deg(make(QUAD))  # type: ignore[operator]
    np.testing.assert_allclose(got, [0, 90, 180, 270], atol=1e-12)


def test_structured_and_raw_buffers() -> None:
    rec = np.zeros(4, dtype=[("x", ">f4"), ("y", "<f8"), ("z", "i2"), ("tag", "u4")])
    rec["x"], rec["y"], rec["z"] = QUAD[:, 0], QUAD[:, 1], QUAD[:, 2]
    np.testing.assert_allclose(gl.azimuth_deg(rec), [0, 90, 180, 270], atol=1e-12)
    raw = QUAD.astype("<f4").tobytes()
    for buf in (raw, bytearray(raw), memoryview(raw)):
        np.testing.assert_allclose(gl.azimuth_deg(buf), [0, 90, 180, 270], atol=1e-12)
    with pytest.raises(ValueError, match="^points: a raw buffer of 16-byte points"):
        gl.azimuth_deg(raw[:-4])
    with pytest.raises(ValueError, match="^points: a structured array needs fields x, y, z"):
        gl.azimuth_deg(np.zeros(3, dtype=[("x", "f4"), ("y", "f4")]))


@pytest.mark.parametrize("empty", [[], np.empty(0), np.empty((0, 3)), np.empty((0, 4), ">f4"), b""])
def test_empty_clouds(empty: object) -> None:
    p = gl.profile()
    assert gl.azimuth_deg(empty).shape == (0,)
    assert gl.apply_profile(p, empty, rated_range_m=100.0).shape == (0,)


def test_no_copy_for_carlas_own_layout() -> None:
    pts = sweep(10)
    assert as_points(pts) is pts
    assert as_points(pts[:, :3]).flags.c_contiguous


def test_sensor_yaw_turns_the_sensor_frame_into_the_vehicle_frame() -> None:
    # A sensor turned 90 degrees to the left (ISO 8855): its "ahead" is the vehicle's left.
    np.testing.assert_allclose(gl.azimuth_deg(QUAD, sensor_yaw_deg=90.0), [90, 180, 270, 0], atol=1e-9)
    p = gl.profile(mode="range", gaze_deg=90.0)
    pts = sweep()
    turned = gl.apply_profile(p, pts, rated_range_m=100.0, sensor_yaw_deg=30.0)
    # The same cloud expressed in the vehicle frame by hand (ISO 8855 axes).
    a = np.radians(30.0)
    x, yl = pts[:, 0].astype(np.float64), -pts[:, 1].astype(np.float64)
    iso = np.column_stack([np.cos(a) * x - np.sin(a) * yl, np.sin(a) * x + np.cos(a) * yl, pts[:, 2]])
    np.testing.assert_array_equal(turned, gl.apply_profile(p, iso, rated_range_m=100.0, frame="iso8855"))
    assert (turned != gl.apply_profile(p, pts, rated_range_m=100.0)).any()
