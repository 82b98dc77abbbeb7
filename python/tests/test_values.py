"""Profile as a value; argument conveniences; docs and reprs."""

from __future__ import annotations

import copy
import inspect
import json
import pathlib
import pickle
import re

import numpy as np
import pytest

import gaze_lidar as gl


def test_pickle_deepcopy_and_equality() -> None:
    p = gl.profile(mode="joint", gaze_deg=45.0)
    q = pickle.loads(pickle.dumps(p))
    assert q == p and q is not p and hash(q) == hash(p)
    d = copy.deepcopy(p)
    assert d == p and d is not p
    assert copy.copy(p) is p  # immutable
    assert p != gl.profile(mode="joint", gaze_deg=46.0)
    assert p != "not a profile"
    assert len({p, q, d}) == 1
    assert gl.Profile(p.to_json()) == p
    for c in ("start_deg", "width_deg", "power_w", "spin_start_rad_s", "spin_end_rad_s", "dwell_s", "in_rof"):
        np.testing.assert_array_equal(getattr(q, c), getattr(p, c))


def test_arrays_are_read_only() -> None:
    p = gl.profile()
    for c in ("start_deg", "power_w", "in_rof"):
        a = getattr(p, c)
        with pytest.raises(ValueError, match="read-only"):
            a[0] = 0
    with pytest.raises(ValueError, match="read-only"):
        p.power_w_at([1.0, 2.0])[0] = 0.0


def test_power_and_spin_at_azimuths() -> None:
    p = gl.profile(mode="joint", gaze_deg=90.0, bins=72)
    starts, widths = p.start_deg, p.width_deg
    rng = np.random.default_rng(2)
    az = rng.uniform(-720, 720, (7, 11))
    # Reference from the documented profile@1 semantics: the bin holding
    # the wrapped azimuth; within it ω² grows linearly in angle.
    w = np.mod(az, 360.0)
    k = np.searchsorted(starts, w, side="right") - 1
    np.testing.assert_array_equal(p.power_w_at(az), p.power_w[k])
    f = (w - starts[k]) / widths[k]
    ws, we = p.spin_start_rad_s[k], p.spin_end_rad_s[k]
    np.testing.assert_allclose(p.spin_rad_s_at(az), np.sqrt(ws**2 + (we**2 - ws**2) * f), rtol=1e-12)
    assert p.power_w_at(az).shape == az.shape
    assert p.power_w_at(90.0).shape == ()
    np.testing.assert_allclose(p.spin_rad_s_at(starts), p.spin_start_rad_s, rtol=1e-12)
    with pytest.raises(ValueError, match="^azimuth_deg: NaN is not a finite angle"):
        p.power_w_at([0.0, float("nan")])


def test_check_takes_a_profile_dict_path_or_text(tmp_path: pathlib.Path) -> None:
    p = gl.profile()
    text = p.to_json()
    path = tmp_path / "p.json"
    path.write_text(text)
    for arg in (p, json.loads(text), path, str(path), text):
        assert gl.check(arg).certified, arg
    with pytest.raises(ValueError, match="^profile: .*nope.json"):
        gl.check(str(tmp_path / "nope.json"))
    with pytest.raises(ValueError, match="^profile: expected"):
        gl.check(3)  # type: ignore[arg-type]


def test_optimize_takes_a_dict_path_or_text(repo: pathlib.Path) -> None:
    import tomllib

    path = repo / "examples/configs/paper.toml"
    text = path.read_text()
    a = gl.optimize(text, 90.0)
    assert gl.optimize(path, 90.0) == a
    assert gl.optimize(str(path), 90.0) == a
    assert gl.optimize(tomllib.loads(text), 90.0) == a
    with pytest.raises(ValueError, match="^config"):
        gl.optimize({"no_such_key": 1}, 90.0)


def test_seed_none_is_fresh_entropy() -> None:
    p = gl.profile(mode="resolution", gaze_deg=90.0)
    rng = np.random.default_rng(0)
    a = np.radians(rng.uniform(60, 120, 4000))
    pts = np.column_stack([10 * np.cos(a), -10 * np.sin(a), np.zeros_like(a)])
    masks = [gl.apply_profile(p, pts, rated_range_m=100.0, seed=None) for _ in range(3)]
    assert any((m != masks[0]).any() for m in masks[1:])
    np.testing.assert_array_equal(
        gl.apply_profile(p, pts, rated_range_m=100.0, seed=7), gl.apply_profile(p, pts, rated_range_m=100.0, seed=7)
    )


def test_version_docs_and_reprs() -> None:
    assert re.fullmatch(r"\d+\.\d+\.\d+.*", gl.__version__)
    sig = inspect.signature(gl.profile)
    assert sig.parameters["gaze_deg"].default == 90.0
    assert "Ellipsis" not in str(sig)
    assert "side the driver is *not* watching" in (gl.profile.__doc__ or "")
    assert "internal lock" in (gl.GazeStream.__doc__ or "")
    assert str(inspect.signature(gl.GazeStream.push)) == "(self, /, t_s, gaze_deg, valid=True)"
    assert "recover_samples=4" in str(inspect.signature(gl.GazeStream))
    p = gl.profile()
    assert re.fullmatch(r"<gaze_lidar\.Profile 360 bins, mode=\"closed-form range\", gaze_deg=90, .* W, .* rad/s>", repr(p)), repr(p)
    s = gl.GazeStream()
    frames = s.push(0.0, 90.0) + s.push(0.05, 90.0)
    assert repr(frames[-1]) == "<gaze_lidar.Frame t_s=0.05 state=fail_safe gaze_deg=None>"
    assert repr(s).startswith("<gaze_lidar.GazeStream preset=\"paper\" mode=\"range\" period_s=0.05 samples=2")


def test_push_many_is_many_pushes() -> None:
    t = np.arange(0, 1.0, 0.01)
    g = np.where(t < 0.5, 90.0, -30.0)
    valid = (t < 0.3) | (t > 0.4)
    a, b = gl.GazeStream(), gl.GazeStream()
    batch = a.push_many(t, g, valid)
    one_by_one = [f for ti, gi, vi in zip(t, g, valid) for f in b.push(float(ti), float(gi), bool(vi))]
    assert [(f.t_s, f.state, f.gaze_deg) for f in batch] == [(f.t_s, f.state, f.gaze_deg) for f in one_by_one]
    assert a.stats == b.stats
    assert {f.state for f in batch} == {"adaptive", "fail_safe"}
    with pytest.raises(ValueError, match="^gaze_deg: t_s, gaze_deg and valid must have one length"):
        gl.GazeStream().push_many(t, g[:-1])
    with pytest.raises(ValueError, match=r"^t_s\[2\]"):
        gl.GazeStream().push_many([0.0, 0.01, float("nan")], [0.0, 0.0, 0.0])
