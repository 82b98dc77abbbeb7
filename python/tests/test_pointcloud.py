"""apply_profile on synthetic clouds with known answers.

Clouds are in CARLA's sensor frame (x forward, y right, z up): a point at
azimuth β (the crate's convention, counter-clockwise from ahead, 90° = left)
and range r is (r cos β, -r sin β, z).
"""

from __future__ import annotations

from typing import Any
import numpy.typing as npt
import math

import numpy as np
import pytest

import gaze_lidar as gl


def cloud(azimuth_deg: npt.ArrayLike, range_m: npt.ArrayLike, z_m: float = 0.0, intensity: float = 1.0) -> npt.NDArray[np.float32]:
    az = np.radians(np.asarray(azimuth_deg, dtype=np.float64))
    r = np.asarray(range_m, dtype=np.float64)
    horizontal = np.sqrt(np.maximum(r**2 - z_m**2, 0.0))
    pts = np.empty((az.size, 4), dtype=np.float32)
    pts[:, 0] = horizontal * np.cos(az)
    pts[:, 1] = -horizontal * np.sin(az)
    pts[:, 2] = z_m
    pts[:, 3] = intensity
    return pts


def true_range(pts: npt.NDArray[Any]) -> npt.NDArray[np.float64]:
    r: npt.NDArray[np.float64] = np.sqrt((pts[:, :3].astype(np.float64) ** 2).sum(axis=1))
    return r


def test_carla_azimuth_convention() -> None:
    pts = np.array([[10, 0, 0, 1], [0, -10, 0, 1], [-10, 0, 0, 1], [0, 10, 0, 1]], dtype=np.float32)
    np.testing.assert_allclose(gl.azimuth_deg(pts), [0, 90, 180, 270], atol=1e-12)
    np.testing.assert_allclose(gl.azimuth_deg(pts, frame="iso8855"), [0, 270, 180, 90], atol=1e-12)
    rng = np.random.default_rng(5)
    az = rng.uniform(0, 360, 1000)
    np.testing.assert_allclose(gl.azimuth_deg(cloud(az, 50.0)), az, atol=1e-4)


def test_uniform_baseline_keeps_exactly_the_points_within_the_rated_range() -> None:
    base = gl.profile(mode="baseline", gaze_deg=None)
    rng = np.random.default_rng(1)
    n = 50_000
    pts = cloud(rng.uniform(0, 360, n), rng.uniform(0.5, 200.0, n), z_m=0.0)
    pts[::3, 2] = rng.uniform(-2, 2, pts[::3].shape[0])  # some height: 3D range counts
    r = true_range(pts)
    pts = pts[np.abs(r - 100.0) > 1e-4]  # float32 rounding aside, no ambiguity
    r = true_range(pts)
    mask = gl.apply_profile(base, pts, rated_range_m=100.0)
    assert mask.dtype == np.bool_ and mask.shape == (pts.shape[0],)
    np.testing.assert_array_equal(mask, r <= 100.0)
    # The rated range is the caller's: the same cloud at 50 m.
    np.testing.assert_array_equal(gl.apply_profile(base, pts, rated_range_m=50.0), r <= 50.0)
    # The intensity column plays no part.
    pts2 = pts.copy()
    pts2[:, 3] = 0.0
    np.testing.assert_array_equal(gl.apply_profile(base, pts2, rated_range_m=100.0), mask)


def test_range_control_keeps_farther_points_outside_the_region_of_focus() -> None:
    p = gl.profile(mode="range", gaze_deg=90.0)  # RoF: 60°–120° (left)
    rng = np.random.default_rng(2)
    n = 100_000
    az = rng.uniform(0, 360, n)
    pts = cloud(az, rng.uniform(1.0, 150.0, n))
    r = true_range(pts)
    mask = gl.apply_profile(p, pts, rated_range_m=100.0)
    rof = (az > 61) & (az < 119)
    roi = (az < 59) | (az > 121)
    far_rof, far_roi = r[rof & mask].max(), r[roi & mask].max()
    near_rof, near_roi = r[rof & ~mask].min(), r[roi & ~mask].min()
    # Every point is kept up to a range and dropped beyond it, per region.
    assert far_rof < near_rof and far_roi < near_roi
    # Half power in the RoF: ≈ 100 m / √2 (slightly more: less clear-air
    # extinction); 1.1 × P̄ outside: < +5 % (R ∝ √P), never the 48→74 m of
    # the argus model's constant factors.
    assert 70.0 < far_rof < 72.0
    assert 104.0 < far_roi < 105.5
    assert mask[roi].mean() > mask[rof].mean()
    # Fog shortens both; the RoI keeps its lead.
    fog = gl.apply_profile(p, pts, rated_range_m=100.0, fog_mor_m=100.0)
    assert r[roi & fog].max() < 40.0 and r[roi & fog].max() > r[rof & fog].max()
    # The paper code's model: a hard 100 m and intensity thresholds in fog.
    argus = gl.apply_profile(p, pts, rated_range_m=100.0, model="argus")
    assert r[argus].max() <= 100.0
    argus_fog = gl.apply_profile(p, pts, rated_range_m=100.0, model="argus", fog_mor_m=200.0)
    # The paper code's model (`docs/reproduction.md`): ≈ 74 m at 1.1 × P̄ in its fog 50; at half power nothing
    # clears the intensity threshold.
    assert 70.0 < r[roi & argus_fog].max() < 76.0
    assert not argus_fog[rof].any()


def test_resolution_control_thins_the_region_of_focus_by_the_spin_ratio() -> None:
    p = gl.profile(mode="resolution", gaze_deg=90.0)
    omega_bar = 2 * math.pi * p.frame_rate_hz
    omega_rof = float(p.spin_start_rad_s[p.in_rof][0])
    omega_roi = float(p.spin_start_rad_s[~p.in_rof][0])
    want = omega_bar / omega_rof
    rng = np.random.default_rng(3)
    n = 200_000
    az = rng.uniform(0, 360, n)
    pts = cloud(az, rng.uniform(1.0, 60.0, n))
    mask = gl.apply_profile(p, pts, rated_range_m=100.0, seed=7)
    rof = (az > 60.5) & (az < 119.5)
    got = mask[rof].mean()
    sigma = math.sqrt(want * (1 - want) / rof.sum())
    assert abs(got - want) < 4 * sigma, (got, want)
    # The RoI spins slower than the cloud was recorded: nothing to thin.
    assert omega_roi < omega_bar
    assert mask[(az < 59.5) | (az > 120.5)].all()
    # Seeded: the same seed gives the same mask, another seed another.
    np.testing.assert_array_equal(gl.apply_profile(p, pts, rated_range_m=100.0, seed=7), mask)
    assert (gl.apply_profile(p, pts, rated_range_m=100.0, seed=8) != mask).any()
    # A cloud recorded at the slowest spin shows the RoI's extra density too.
    dense = gl.apply_profile(p, pts, rated_range_m=100.0, seed=7, cloud_spin_rad_s=omega_roi)
    assert mask[rof].mean() > dense[rof].mean() > 0
    assert dense[(az < 59.5) | (az > 120.5)].all()
    ratio = dense[rof].mean()
    assert abs(ratio - omega_roi / omega_rof) < 4 * math.sqrt(ratio * (1 - ratio) / rof.sum())


def test_layouts_and_errors() -> None:
    p = gl.profile(mode="range", gaze_deg=90.0)
    pts = cloud(np.linspace(0, 359, 100), 50.0)
    want = gl.apply_profile(p, pts, rated_range_m=100.0)
    np.testing.assert_array_equal(gl.apply_profile(p, pts.astype(np.float64), rated_range_m=100.0), want)
    np.testing.assert_array_equal(gl.apply_profile(p, pts[:, :3], rated_range_m=100.0), want)
    strided = np.asfortranarray(pts)
    np.testing.assert_array_equal(gl.apply_profile(p, strided, rated_range_m=100.0), want)
    assert gl.apply_profile(p, np.zeros((0, 4), np.float32), rated_range_m=100.0).shape == (0,)
    with pytest.raises(ValueError, match="^points: "):
        gl.apply_profile(p, pts[:, :2], rated_range_m=100.0)
    with pytest.raises(ValueError, match="^points: "):
        gl.apply_profile(p, pts.astype(np.complex64), rated_range_m=100.0)
    with pytest.raises(ValueError, match="^points: "):
        gl.apply_profile(p, pts[:, :, None], rated_range_m=100.0)
    bad = pts.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"^points\[3\]"):
        gl.apply_profile(p, bad, rated_range_m=100.0)
    with pytest.raises(ValueError, match="^rated_range_m"):
        gl.apply_profile(p, pts, rated_range_m=-1.0)
    with pytest.raises(ValueError, match="^fog_mor_m"):
        gl.apply_profile(p, pts, rated_range_m=100.0, fog_mor_m=0.0)
    with pytest.raises(ValueError, match="^fog_mor_m"):
        gl.apply_profile(p, pts, rated_range_m=100.0, model="argus", fog_mor_m=150.0)
    with pytest.raises(ValueError, match="^model"):
        gl.apply_profile(p, pts, rated_range_m=100.0, model="lambertian")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="^frame"):
        gl.apply_profile(p, pts, rated_range_m=100.0, frame="enu")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="^seed"):
        gl.apply_profile(p, pts, rated_range_m=100.0, seed=-1)
    with pytest.raises(TypeError):
        gl.apply_profile(p, pts)  # type: ignore[call-arg]  # rated_range_m is required
