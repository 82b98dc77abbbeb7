"""Profiles, the checker, firmware tables and errors."""

from __future__ import annotations

import pathlib
from typing import Any
import json
import math

import numpy as np
import pytest

import gaze_lidar as gl

COLUMNS = ("start_deg", "width_deg", "power_w", "spin_start_rad_s", "spin_end_rad_s")


def test_paper_range_profile_has_equal_float64_arrays() -> None:
    p = gl.profile(preset="paper", mode="range", gaze_deg=90.0)
    arrays = [getattr(p, c) for c in COLUMNS]
    assert all(isinstance(a, np.ndarray) and a.dtype == np.float64 for a in arrays)
    assert len({a.shape for a in arrays}) == 1
    assert len(p.start_deg) >= 360 == len(p)
    # The bins tile [0, 360) in order.
    assert p.start_deg[0] == 0.0
    np.testing.assert_allclose(p.start_deg[1:], (p.start_deg + p.width_deg)[:-1], rtol=0, atol=1e-9)
    assert math.isclose(float(p.width_deg.sum()), 360.0, rel_tol=1e-12)
    # Eq. 4: half power in the 60° region of focus around 90°, 1.1 × P̄ elsewhere.
    rof = p.in_rof
    assert math.isclose(float(p.width_deg[rof].sum()), 60.0, rel_tol=1e-9)
    np.testing.assert_allclose(p.power_w[rof], 0.5e-3, rtol=1e-12)
    np.testing.assert_allclose(p.power_w[~rof], 1.1e-3, rtol=1e-9)
    s = p.summary
    assert math.isclose(s["average_power_angle_w"], p.average_power_w, rel_tol=1e-9)
    assert p.gaze_deg == 90.0 and p.power_accounting == "angle"


def test_certified_json_passes_the_checker() -> None:
    p = gl.profile(preset="paper", mode="range", gaze_deg=90.0)
    v = gl.check(p.to_json())
    assert v.certified is True and bool(v)
    assert v.violations == [] and v.limits == []
    assert v.worst_ratio is not None and 0.0 < v.worst_ratio < 1.0
    assert isinstance(v.binding_rule, str) and v.binding_rule
    assert gl.check(p.to_json(), preset="paper").certified


def test_tripling_one_bins_power_is_rejected_naming_the_limit() -> None:
    p = gl.profile(preset="paper", mode="range", gaze_deg=90.0)
    doc = json.loads(p.to_json())
    doc["bins"][200]["power_w"] *= 3.0
    v = gl.check(json.dumps(doc))
    assert v.certified is False and not v
    assert "power_w_max" in v.limits
    assert any("bins[200].power_w" in m and "limits.power_w_max" in m for m in v.violations)
    # Three times the power is also over the Class 1 limit at that azimuth.
    assert "eye_safety" in v.limits and v.worst_ratio is not None and v.worst_ratio > 1.0
    with pytest.raises(gl.Rejected) as e:
        gl.Profile.from_json(json.dumps(doc))
    assert any("limits.power_w_max" in m for m in e.value.violations)


def test_nan_gaze_is_a_value_error_naming_gaze_deg() -> None:
    with pytest.raises(ValueError, match="gaze_deg"):
        gl.profile(gaze_deg=float("nan"))
    with pytest.raises(ValueError, match="gaze_deg"):
        gl.profile(gaze_deg=1e9)
    with pytest.raises(ValueError, match="gaze_deg"):
        gl.optimize("bins = 36", float("inf"))


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"preset": "nope"}, "preset"),
        ({"mode": "sideways"}, "mode"),
        ({"bins": 3}, "bins"),
        ({"bins": -1}, "bins"),
        ({"accounting": "energy"}, "accounting"),
        ({"mode": "range", "gaze_deg": None}, "gaze_deg"),
    ],
)
def test_bad_arguments_name_the_field(kwargs: dict[str, Any], field: str) -> None:
    with pytest.raises(ValueError) as e:
        gl.profile(**kwargs)
    assert str(e.value).startswith(field), str(e.value)
    assert "\n" not in str(e.value)


def test_baseline_needs_no_gaze_and_modes_differ() -> None:
    base = gl.profile(mode="baseline", gaze_deg=None)
    assert base.gaze_deg is None
    assert np.all(base.power_w == base.average_power_w)
    res = gl.profile(mode="resolution", gaze_deg=90.0, bins=720)
    assert len(res) >= 720
    spin = res.spin_start_rad_s
    assert spin[res.in_rof].min() > spin[~res.in_rof].max()
    assert math.isclose(float(res.dwell_s.sum()), 1.0 / res.frame_rate_hz, rel_tol=1e-9)
    t = gl.profile(mode="joint", gaze_deg=90.0, accounting="time")
    assert t.power_accounting == "time"
    assert math.isclose(t.summary["average_power_time_w"], t.average_power_w, rel_tol=1e-9)


def test_a_closed_form_the_motor_cannot_follow_is_rejected() -> None:
    # The VLS-128 preset limits the motor's acceleration: no spin steps.
    with pytest.raises(gl.Rejected, match="spin_accel_rad_s2_max") as e:
        gl.profile(preset="vls128", mode="resolution", gaze_deg=90.0)
    assert len(e.value.violations) > 1


def test_json_round_trip() -> None:
    p = gl.profile(mode="joint", gaze_deg=250.0)
    q = gl.Profile.from_json(p.to_json())
    for c in COLUMNS:
        np.testing.assert_array_equal(getattr(p, c), getattr(q, c))
    assert q.to_json() == p.to_json()
    with pytest.raises(ValueError, match="format"):
        gl.Profile.from_json(p.to_json().replace("profile@1", "profile@9"))
    with pytest.raises(ValueError, match=r"^profile_json:1:2: "):
        gl.check("{not json")


def test_firmware_tables_are_integer_arrays_that_sum_to_the_frame() -> None:
    p = gl.profile(mode="range", gaze_deg=90.0)
    fw = p.firmware()
    assert fw["format"] == "gaze-lidar/firmware@1" and fw["tick_hz"] == 80_000_000
    for k in ("width_mdeg", "dwell_ticks", "power_code", "dwell_ticks_min", "dwell_ticks_max", "power_code_cap"):
        assert np.issubdtype(fw[k].dtype, np.integer), k
        assert fw[k].shape == (len(p),)
    assert int(fw["dwell_ticks"].sum()) == fw["frame_ticks"] == 4_000_000
    assert np.all(fw["power_code"] <= fw["power_code_cap"])
    # Power codes follow the profile's power (rounded down, never up).
    np.testing.assert_array_less(fw["power_code"] * fw["power_w_per_code"], p.power_w * (1 + 1e-12))
    assert json.loads(p.firmware_json())["frame_ticks"] == fw["frame_ticks"]
    with pytest.raises(ValueError, match="tick_hz"):
        p.firmware(tick_hz=0)
    with pytest.raises(ValueError, match="tick_hz"):
        p.firmware(tick_hz=-5)


def test_optimizer_from_a_toml_config(repo: pathlib.Path) -> None:
    cfg = (repo / "examples/configs/paper.toml").read_text()
    p = gl.optimize(cfg, 90.0)
    closed = gl.profile(mode="joint", gaze_deg=90.0)
    assert gl.check(p.to_json()).certified
    # The paper's problem: the optimum is the closed form (`specs/optimizer.md`).
    np.testing.assert_allclose(np.sort(p.power_w), np.sort(closed.power_w), rtol=1e-6)
    with pytest.raises(ValueError, match="^config: "):
        gl.optimize("[lidar]\nfoo = 1\n", 90.0)
    infeasible = cfg.replace("[levels]", "[limits]\nspin_rad_s_max = 100.0\n\n[levels]")
    with pytest.raises(gl.Infeasible, match="spin_rad_s_max"):
        gl.optimize(infeasible, 90.0)


def test_optimized_profile_reports_range_and_density_per_region(repo: pathlib.Path) -> None:
    # examples/configs/paper.toml: the optimum is the paper's closed form,
    # so its figures are the closed form's. By hand: the paper's 100 m
    # rating at P̄ = 1 mW, clear air (α₀ = 2.996/20 km): 1.1 P̄ reaches
    # R = 100·√1.1·e^(−α₀(R − 100)) = 104.805 m, 0.5 P̄ 71.018 m; the spin
    # outside is ω_low = 2π·20·(60/5.4 + 300)/360 rad/s = 6222.2 °/s, so
    # 7812.5 / 6222.2 = 1.25558 points per degree, 5.4 times fewer inside.
    p = gl.optimize((repo / "examples/configs/paper.toml").read_text(), 90.0)
    opt = p.optimality
    assert opt is not None and opt["figures"] == p.figures
    f = p.figures
    assert f is not None
    rof, roi = f["profile"]["rof"], f["profile"]["roi"]
    assert (rof["width_deg"], roi["width_deg"]) == (60.0, 300.0)
    assert rof["range_m"]["mean"] == pytest.approx(71.018, abs=1e-3)
    assert roi["range_m"]["mean"] == pytest.approx(104.805, abs=1e-3)
    assert roi["points_per_deg"]["mean"] == pytest.approx(1.25558, abs=1e-4)
    assert rof["points_per_deg"]["mean"] == pytest.approx(1.25558 / 5.4, abs=1e-4)
    for region in ("rof", "roi"):
        for key in ("range_m", "points_per_deg"):
            a = f["profile"][region][key]
            assert a["min"] <= a["mean"] * (1 + 1e-12) and a["mean"] <= a["max"] * (1 + 1e-12)
            assert a == pytest.approx(f["closed_form"][region][key], rel=1e-9)
    # The per-bin arrays give the same region split and density.
    inside = p.in_rof
    dens = p.pulse_rate_hz * p.dwell_s / p.width_deg
    w = p.width_deg
    assert float(np.sum(w[inside] * dens[inside]) / np.sum(w[inside])) == pytest.approx(
        rof["points_per_deg"]["mean"], rel=1e-12
    )
    # The closed forms carry no optimality block: their figures are their
    # own only (no closed form to compare with); JSON keeps the figures.
    closed = gl.profile(mode="joint", gaze_deg=90.0)
    assert closed.optimality is None
    cf = closed.figures
    assert cf is not None and set(cf) == {"profile"}
    assert gl.Profile.from_json(p.to_json()).figures == f


def test_check_certifies_heads_and_names_them() -> None:
    # A real head's closed-form profile is certified for the whole head
    # (every channel that can meet the aperture, summed), and says so; the
    # paper preset has no head: one channel.
    for name, channels in [("vls128", 128), ("vlp16", 16), ("os1-128", 128)]:
        p = gl.profile(preset=name, mode="range", gaze_deg=90.0)
        v = gl.check(p.to_json(), preset=name)
        assert v.certified, v.violations
        assert v.head_channels == channels
        assert v.power_scale_to_certify is not None and v.power_scale_to_certify >= 1.0
    v = gl.check(gl.profile(preset="paper", mode="range", gaze_deg=90.0).to_json())
    assert v.certified and v.head_channels is None
