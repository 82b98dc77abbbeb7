"""Property tests (hypothesis): any array layout, against plain numpy.

The references are written from the documented semantics, not from the
code: a point (x, y, z) is read as ``np.asarray(a, dtype=np.float64)[:, :3]``
(numpy's conversion rules; float32 and float16 widen exactly, longdouble
rounds to float64); its azimuth (README, "Angles") is
``atan2(-y, x)`` in CARLA's frame and ``atan2(y, x)`` in ISO 8855, in
degrees, wrapped into [0, 360); the uniform baseline keeps exactly the
points with x² + y² + z² ≤ rated_range_m²; under range control a point is
kept iff its distance is within a range that depends only on the power at
its azimuth (``Profile.power_w_at``), so within one power level the kept
points are exactly the nearest ones.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import gaze_lidar as gl

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])

BASELINE = gl.profile(mode="baseline", gaze_deg=None)
RANGE = gl.profile(mode="range", gaze_deg=90.0)
RATED_M = 100.0


def float_arrays(draw: st.DrawFn, dtype: np.dtype[Any], shape: tuple[int, int]) -> npt.NDArray[Any]:
    width = 8 * dtype.itemsize if dtype.kind == "f" else 64
    if dtype.kind == "f":
        elements = st.floats(-300.0, 300.0, width=min(width, 64), allow_subnormal=False)  # type: ignore[arg-type]
    else:
        info = np.iinfo(dtype)
        elements = st.integers(max(int(info.min), -300), min(int(info.max), 300))
    return draw(hnp.arrays(dtype, shape, elements=elements))


@st.composite
def clouds(draw: st.DrawFn) -> npt.NDArray[Any]:
    """N×3 or N×4 arrays of every real dtype and byte order, in C order,
    Fortran order, as strided row views, column views of a wider array, or
    reversed; N from 0."""
    dtype = draw(
        st.one_of(
            hnp.floating_dtypes(sizes=(16, 32, 64), endianness="?"),
            hnp.integer_dtypes(endianness="?"),
            hnp.unsigned_integer_dtypes(endianness="?"),
            st.just(np.dtype(np.longdouble)),
        )
    )
    n = draw(st.integers(0, 40))
    cols = draw(st.sampled_from([3, 4]))
    if dtype == np.longdouble:
        base = float_arrays(draw, np.dtype(np.float64), (n, cols)).astype(np.longdouble)
        base = base + np.longdouble(draw(st.sampled_from([0.0, 1e-17])))
    else:
        base = float_arrays(draw, dtype, (n, cols))
    layout = draw(st.sampled_from(["c", "fortran", "rows", "columns", "reversed", "transposed"]))
    if layout == "fortran":
        return np.asfortranarray(base)
    if layout == "rows":
        step = draw(st.integers(2, 4))
        wide = np.zeros((n * step, cols), dtype=dtype)
        wide[::step] = base
        return wide[::step]
    if layout == "columns":
        wide = np.zeros((n, cols + 3), dtype=dtype)
        wide[:, 1 : 1 + cols] = base
        return wide[:, 1 : 1 + cols]
    if layout == "reversed":
        return np.ascontiguousarray(base[::-1])[::-1]
    if layout == "transposed":
        return np.ascontiguousarray(base.T).T
    return base


def reference_xyz(a: npt.NDArray[Any]) -> npt.NDArray[np.float64]:
    return np.asarray(a, dtype=np.float64)[:, :3]


def reference_azimuth_deg(xyz: npt.NDArray[np.float64], frame: str) -> npt.NDArray[np.float64]:
    y_left = -xyz[:, 1] if frame == "carla" else xyz[:, 1]
    deg = np.degrees(np.arctan2(y_left, xyz[:, 0]))
    wrapped = np.mod(deg, 360.0)
    return np.where(wrapped >= 360.0, 0.0, wrapped)


def circular_gap_deg(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    d = np.abs(a - b) % 360.0
    return np.minimum(d, 360.0 - d)


@SETTINGS
@given(clouds(), st.sampled_from(["carla", "iso8855"]))
def test_azimuth_matches_numpy(a: npt.NDArray[Any], frame: Any) -> None:
    got = gl.azimuth_deg(a, frame)
    want = reference_azimuth_deg(reference_xyz(a), frame)
    assert got.shape == (a.shape[0],) and got.dtype == np.float64
    assert ((got >= 0.0) & (got < 360.0)).all()
    assert (circular_gap_deg(got, want) <= 1e-9).all(), (got, want)


@SETTINGS
@given(clouds(), st.sampled_from(["carla", "iso8855"]), st.integers(0, 2**64 - 1))
def test_baseline_keeps_exactly_the_points_within_the_rated_range(
    a: npt.NDArray[Any], frame: Any, seed: int
) -> None:
    xyz = reference_xyz(a)
    r2 = xyz[:, 0] * xyz[:, 0] + xyz[:, 1] * xyz[:, 1] + xyz[:, 2] * xyz[:, 2]
    clear = np.abs(np.sqrt(r2) - RATED_M) > 1e-6 * RATED_M  # the calibration's rounding aside
    mask = gl.apply_profile(BASELINE, a, rated_range_m=RATED_M, frame=frame, seed=seed)
    assert mask.shape == (a.shape[0],) and mask.dtype == np.bool_
    np.testing.assert_array_equal(mask[clear], (r2 <= RATED_M**2)[clear])


@SETTINGS
@given(clouds(), st.sampled_from(["carla", "iso8855"]), st.integers(0, 2**64 - 1))
def test_range_control_is_a_distance_threshold_per_power_level(
    a: npt.NDArray[Any], frame: Any, seed: int
) -> None:
    xyz = reference_xyz(a)
    mask = gl.apply_profile(RANGE, a, rated_range_m=RATED_M, frame=frame, seed=seed)
    # The layout does not matter: the same points in numpy's canonical layout.
    np.testing.assert_array_equal(
        mask, gl.apply_profile(RANGE, np.ascontiguousarray(xyz), rated_range_m=RATED_M, frame=frame, seed=seed)
    )
    r2 = xyz[:, 0] * xyz[:, 0] + xyz[:, 1] * xyz[:, 1] + xyz[:, 2] * xyz[:, 2]
    power = RANGE.power_w_at(reference_azimuth_deg(xyz, frame))
    for level in np.unique(power):
        at = power == level
        kept, dropped = r2[at & mask], r2[at & ~mask]
        if kept.size and dropped.size:
            assert kept.max() < dropped.min(), (level, kept.max(), dropped.min())
    # More power, no less range: the high-power points reach at least as far.
    lo, hi = power.min(initial=0.0), power.max(initial=0.0)
    if lo < hi:
        assert not (mask[(power == lo)] & (r2[power == lo] > r2[(power == hi) & ~mask].min(initial=np.inf))).any()
