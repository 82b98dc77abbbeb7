"""The package where researchers run it: process pools,
Ctrl-C, pickling, gaze files, per-trial results, DataFrames, figures,
defined terms, CARLA's default range."""

from __future__ import annotations

import math
import multiprocessing
import os
import pathlib
import pickle
import re
import signal
import subprocess
import sys
import threading
import time
import warnings
from typing import Any

import numpy as np
import pytest

import gaze_lidar as gl

SMALL: dict[str, Any] = {"trials": 2, "seed": 3, "variants": ["baseline", "range"], "fog_pct": [0]}


CONFIG = pathlib.Path(__file__).resolve().parents[2] / "examples" / "configs" / "multi_level.toml"


def _simulate_in_child() -> list[dict[str, Any]]:
    return list(gl.simulate(**SMALL))


def _optimize_in_child() -> list[float]:
    return [float(x) for x in gl.optimize(CONFIG, 90.0).power_w]


def test_forked_worker_simulates_after_the_parent_did() -> None:
    parent = list(gl.simulate(**SMALL))  # the parent's threads exist now
    optimized = _optimize_in_child()  # and the solver's
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(1) as pool:
        child = pool.apply_async(_simulate_in_child).get(timeout=120)
        assert pool.apply_async(_optimize_in_child).get(timeout=120) == optimized
    assert child == parent


def _interrupt_after(seconds: float) -> threading.Timer:
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(), reason="signals reach the main thread")
def test_ctrl_c_stops_a_long_simulate_within_a_second() -> None:
    # 24,000 cells: ≈ 13 s on two idle cores (the 2,400-cell grid takes
    # ≤ 1.3 s), minutes on a loaded machine. Ctrl-C after 0.5 s must take
    # effect well before the end.
    timer = _interrupt_after(0.5)
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            gl.simulate(model="argus", trials=2000, seed=1)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 1.5
    # The interpreter and the package work on afterwards.
    assert len(gl.simulate(**SMALL)) == 2


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(), reason="signals reach the main thread")
def test_ctrl_c_returns_from_a_long_check_within_a_second() -> None:
    text = gl.profile("vls128", mode="range", gaze_deg=90.0, bins=36000).to_json()
    start = time.monotonic()
    gl.check(text, "vls128")
    one = time.monotonic() - start
    if one < 1.0:
        pytest.skip(f"one vls128 check takes {one:.2f} s here: nothing long to interrupt")
    timer = _interrupt_after(0.3)
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            for _ in range(100):
                gl.check(text, "vls128")
    finally:
        timer.cancel()
    assert time.monotonic() - start < 1.3


def test_frame_and_verdict_pickle_and_round_trip_equal() -> None:
    s = gl.GazeStream()
    frames = s.push_many(np.arange(0, 0.5, 0.01), np.full(50, 60.0))
    assert {f.state for f in frames} == {"adaptive", "fail_safe"}
    for f in frames:
        g = pickle.loads(pickle.dumps(f))
        assert isinstance(g, gl.Frame)
        assert g == f and (g.t_s, g.state, g.gaze_deg, g.profile) == (f.t_s, f.state, f.gaze_deg, f.profile)
    assert frames[0] != frames[-1] and frames[0] != "frame"
    with pytest.raises(ValueError, match="^state: 'lost'"):
        gl.Frame(0.0, "lost", frames[0].profile)  # type: ignore[arg-type]
    good = gl.check(gl.profile("paper"), "paper")
    # Declared for another sensor: rejected against the paper's.
    rejected = gl.check(gl.profile("vlp16", mode="baseline", gaze_deg=None), "paper")
    assert good and not rejected and rejected.violations
    for v in (good, rejected):
        w = pickle.loads(pickle.dumps(v))
        assert isinstance(w, gl.Verdict) and w == v and w.to_dict() == v.to_dict()
    assert good != rejected
    # Simulation results pickle too.
    r = gl.simulate(**SMALL)
    r2 = pickle.loads(pickle.dumps(r))
    assert r2 == r and r2.trials == r.trials


def test_read_gaze_reads_every_format_the_cli_reads(repo: pathlib.Path, tmp_path: pathlib.Path) -> None:
    data = repo / "tests" / "data" / "gaze"
    assert gl.GAZE_FORMATS == ["jsonl", "csv", "varjo", "neon"]
    # loss_200hz.jsonl has a malformed line 151 (`"gaze_deg": ninety`): a
    # recorded file with one is an error, as in `gaze-lidar stream --input`.
    with pytest.raises(ValueError, match=r"loss_200hz\.jsonl:151: "):
        gl.read_gaze(data / "loss_200hz.jsonl", format="jsonl")
    lines = (data / "loss_200hz.jsonl").read_text().splitlines(keepends=True)
    good = tmp_path / "loss_200hz_fixed.jsonl"
    good.write_text("".join(lines[:150] + lines[151:]))
    files = {"jsonl": good, "csv": data / "right.csv", "varjo": data / "varjo_base.csv", "neon": data / "neon_gaze.csv"}
    for fmt, path in files.items():
        track = gl.read_gaze(path, format=fmt)  # type: ignore[arg-type]
        assert set(track) == {"t_s", "gaze_deg", "valid"}
        n = len(track["t_s"])
        assert n > 1 and len(track["gaze_deg"]) == n and track["valid"].dtype == np.bool_
        assert np.all(np.diff(track["t_s"]) > 0)
        # push_many takes a track as it is.
        assert gl.GazeStream().push_many(**track)
    # Written from the files and the formats' documentation, not the code:
    csv = gl.read_gaze(data / "right.csv", format="csv")
    assert csv["t_s"][:2].tolist() == [0.0, 0.01] and csv["gaze_deg"][:2].tolist() == [270.0, 270.1]
    jsonl = gl.read_gaze(good)
    assert jsonl["t_s"][:2].tolist() == [0.0, 0.005] and jsonl["gaze_deg"][0] == 89.9
    # Neon: azimuth positive to the right of the scene camera → gaze −10°.
    neon = gl.read_gaze(data / "neon_gaze.csv", format="neon")
    assert neon["gaze_deg"][0] == pytest.approx(-10.0) and neon["t_s"][1] - neon["t_s"][0] == pytest.approx(0.005, abs=1e-6)
    # Varjo: head yaw 30° (quaternion y = −sin 15°) plus the eye 20° to the
    # right (x = −sin 20°) in HMD axes (x right): the head turned by
    # −30° about up… the azimuth is atan2(−x_w, z_w) of the rotated gaze.
    varjo = gl.read_gaze(data / "varjo_base.csv", format="varjo")
    qx, qy, qz, qw = 0.0, -0.258819, 0.0, 0.965926
    v = np.array([-0.342020, 0.0, 0.939693])
    u = np.array([qx, qy, qz])
    w = v + 2 * qw * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))
    assert varjo["gaze_deg"][0] == pytest.approx(math.degrees(math.atan2(-w[0], w[2])), abs=1e-3)


def test_read_gaze_errors_name_file_line_and_field(tmp_path: pathlib.Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,gaze_deg\n0.0,90\n0.01,ninety\n")
    with pytest.raises(ValueError, match=r"bad\.csv:3: .*gaze_deg"):
        gl.read_gaze(bad, format="csv")
    bom = tmp_path / "bom.jsonl"
    bom.write_bytes(b'\xef\xbb\xbf{"t_s": 0, "gaze_deg": 1}\n')
    with pytest.raises(ValueError, match=r"bom\.jsonl:1: .*byte-order mark"):
        gl.read_gaze(bom)
    with pytest.raises(ValueError, match="^format: 'tobii' is not one of jsonl, csv, varjo, neon"):
        gl.read_gaze(bad, format="tobii")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="^path: .*missing"):
        gl.read_gaze(tmp_path / "missing.csv", format="csv")


def test_import_gaze_lidar_makes_carla_an_attribute() -> None:
    # A fresh interpreter: this one may have imported gaze_lidar.carla already.
    code = "import gaze_lidar as gl; print(gl.carla.check_blueprint.__name__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "check_blueprint"


def test_simulate_gives_per_trial_records_and_tables() -> None:
    r = gl.simulate(model="argus", trials=6, seed=5, variants=["baseline", "range"], fog_pct=[0, 50])
    assert isinstance(r, list) and len(r) == 4
    assert len(r.trials) == 4 * 6
    assert list(r.trials[0]) == [
        "model",
        "variant",
        "fog_pct",
        "trial",
        "tta_right_s",
        "tta_left_s",
        "hybrid_right_s",
        "hybrid_left_s",
        "roi_points",
        "roi_pulses",
        "duration_s",
        "density_pts_per_deg_s",
        "fail_safe_frames",
        "detected_in_fail_safe",
        "false_alarms",
        "early_false_tta_s",
    ]
    # A constant gaze never runs a fail-safe frame; the default detector has no false alarms.
    assert all(t["fail_safe_frames"] == 0 and t["false_alarms"] == 0 for t in r.trials)
    assert all(t["detected_in_fail_safe"] in (False, None) for t in r.trials)
    # Each row's median and count are those of its trials (numpy's median).
    for row in r:
        cell = [t for t in r.trials if (t["model"], t["variant"], t["fog_pct"]) == (row["model"], row["variant"], row["fog_pct"])]
        assert sorted(t["trial"] for t in cell) == list(range(6))
        tta = [t["tta_right_s"] for t in cell if t["tta_right_s"] is not None]
        assert row["detected"] == len(tta)
        if tta:
            assert row["tta_median_s"] == pytest.approx(float(np.median(tta)), rel=1e-12)
    d = r.to_dict()
    assert d["rows"] == list(r) and d["trials"] == r.trials
    pd = pytest.importorskip("pandas")
    rows = r.to_pandas()
    trials = r.to_pandas("trials")
    assert isinstance(rows, pd.DataFrame) and len(rows) == 4 and "tta_median_s" in rows
    assert len(trials) == 24 and trials["trial"].max() == 5
    with pytest.raises(ValueError, match="^what: "):
        r.to_pandas("cells")  # type: ignore[arg-type]


def test_frames_profiles_and_verdicts_as_dicts_and_frames() -> None:
    s = gl.GazeStream()
    frames = s.push_many(np.arange(0, 0.3, 0.01), np.full(30, 90.0))
    d = frames[-1].to_dict()
    assert d == {"t_s": frames[-1].t_s, "state": "adaptive", "gaze_deg": 90.0, "mode": "closed-form range"}
    cols = frames[-1].profile.to_dict()
    assert set(cols) >= {"start_deg", "width_deg", "power_w", "dwell_s", "in_rof", "range_m", "points_per_deg"}
    np.testing.assert_array_equal(cols["power_w"], frames[-1].profile.power_w)
    pd = pytest.importorskip("pandas")
    table = gl.frames_to_pandas(frames)
    assert list(table.columns) == ["t_s", "state", "gaze_deg", "mode"] and len(table) == len(frames)
    bins = frames[-1].to_pandas()
    assert len(bins) == 360 and (bins["t_s"] == frames[-1].t_s).all() and (bins["state"] == "adaptive").all()
    assert isinstance(gl.check(gl.profile()).to_pandas(), pd.DataFrame)


def test_to_pandas_without_pandas_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas → ImportError
    r = gl.simulate(**SMALL)
    frame = gl.GazeStream().push(0.0, 90.0)[0]
    for call in (r.to_pandas, frame.to_pandas, frame.profile.to_pandas, gl.check(gl.profile()).to_pandas):
        with pytest.raises(ImportError, match=r"needs pandas, which is not installed: `pip install pandas`"):
            call()
    assert r.to_dict()["rows"] == list(r)


def test_closed_forms_have_range_and_points_per_degree_figures() -> None:
    rated_m = 100.0  # the paper preset's rated range (model/presets.rs)
    base = gl.profile("paper", mode="baseline", gaze_deg=None)
    f = base.figures
    assert f is not None and set(f) == {"profile"} and f["profile"]["rof"] is None
    roi = f["profile"]["roi"]
    assert roi["width_deg"] == pytest.approx(360.0)
    assert roi["range_m"]["mean"] == pytest.approx(rated_m, rel=1e-9)
    for mode in ("range", "resolution", "joint"):
        p = gl.profile("paper", mode=mode, gaze_deg=90.0)
        assert p.preset == "paper"
        fig = p.figures
        assert fig is not None
        cols = p.to_dict()
        # From the documented definitions: the range R solves the range
        # equation (P/P̄)·(R₀/R)²·e^(−2α₀(R − R₀)) = 1, α₀ = 2.996 / 20 km
        # (clear air), ≈ R₀·√(P/P̄); points per degree = pulse rate × dwell / width.
        r, alpha0 = cols["range_m"], 2.996 / 20_000.0
        signal = p.power_w / p.average_power_w * (rated_m / r) ** 2 * np.exp(-2 * alpha0 * (r - rated_m))
        np.testing.assert_allclose(signal, 1.0, rtol=1e-9)
        np.testing.assert_allclose(r, rated_m * np.sqrt(p.power_w / p.average_power_w), rtol=1e-2)
        np.testing.assert_allclose(cols["points_per_deg"], p.pulse_rate_hz * p.dwell_s / p.width_deg, rtol=1e-12)
        for region, mask in (("rof", p.in_rof), ("roi", ~p.in_rof)):
            r = fig["profile"][region]
            w = p.width_deg[mask]
            assert r["width_deg"] == pytest.approx(w.sum())
            assert r["range_m"]["max"] == pytest.approx(cols["range_m"][mask].max())
            assert r["points_per_deg"]["mean"] == pytest.approx((cols["points_per_deg"][mask] * w).sum() / w.sum())
    # A pickled closed form keeps its figures; JSON alone has none.
    p = gl.profile("paper", mode="range")
    assert pickle.loads(pickle.dumps(p)).figures == p.figures
    assert gl.Profile.from_json(p.to_json()).figures is None
    assert gl.Profile(p.to_json(), "paper").figures == p.figures


def test_every_term_the_docs_use_is_defined() -> None:
    doc = gl.__doc__ or ""
    terms = doc.split("Terms (as the code uses them):", 1)
    assert len(terms) == 2, "the package docs have a Terms section"
    glossary = terms[1]
    defined = {m.group(1).lower() for m in re.finditer(r"^- \*([^*]+)\*", glossary, re.M)}
    stub = (pathlib.Path(gl.__file__).parent / "_native.pyi").read_text(encoding="utf-8")
    docs = [stub, doc] + [
        o.__doc__ or ""
        for m in (gl, gl.carla)
        for o in vars(m).values()
        if callable(o) and getattr(o, "__module__", "").startswith("gaze_lidar")
    ]
    text = " ".join(docs).lower()
    for term in ("clear air", "rated range", "reference reflectivity", "region of focus", "points per degree", "fail-safe", "tta", "fog"):
        if re.search(rf"\b{re.escape(term)}\b", text):
            assert term in defined, f"{term!r} is used in the docs but not defined in the Terms section"
    assert re.search(r"\*clear air\*: a meteorological optical range \(MOR\) of 20 km", glossary)


class _Blueprint:
    def __init__(self, **attrs: float) -> None:
        self.attrs = attrs

    def has_attribute(self, name: str) -> bool:
        return name in self.attrs

    def get_attribute(self, name: str) -> str:
        return str(self.attrs[name])


def test_check_blueprint_flags_a_range_shorter_than_the_profile_reaches() -> None:
    base = gl.profile("paper", mode="baseline", gaze_deg=None)  # rated 100 m
    rng = gl.profile("paper", mode="range", gaze_deg=90.0)  # farther outside the focus
    ok = {"rotation_frequency": 20.0, "dropoff_general_rate": 0.0, "dropoff_zero_intensity": 0.0}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        problems = gl.carla.check_blueprint(_Blueprint(range=10.0, **ok), base)
    assert len(problems) == 1 and len(caught) == 1
    assert problems[0].startswith("range: 10 m (CARLA's default) is shorter than the 100 m the profile reaches")
    assert gl.carla.check_blueprint(_Blueprint(range=100.0, **ok), base, warn=False) == []
    far = gl.carla.profile_range_m(rng)
    assert far is not None and far > 100.0
    assert gl.carla.check_blueprint(_Blueprint(range=100.0, **ok), rng, warn=False)[0].startswith("range: 100 m is shorter")
    assert gl.carla.check_blueprint(_Blueprint(range=math.ceil(far), **ok), rng, warn=False) == []
    # A profile read from JSON knows no preset: the rated range is given.
    bare = gl.Profile.from_json(base.to_json())
    assert gl.carla.check_blueprint({"range": 10.0}, bare, warn=False) == []
    assert gl.carla.check_blueprint({"range": 10.0}, bare, rated_range_m=100.0, warn=False)[0].startswith("range: 10 m")
