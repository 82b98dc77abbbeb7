"""GazeStream: the frame clock, fail-safe on silence and loss."""

from __future__ import annotations

import pathlib
import numpy as np
import pytest

import gaze_lidar as gl


def fixations(stream: gl.GazeStream, until_s: float, gaze_deg: float = 90.0, rate_hz: float = 200.0) -> list[gl.Frame]:
    frames = []
    for k in range(int(round(until_s * rate_hz)) + 1):
        frames += stream.push(k / rate_hz, gaze_deg)
    return frames


def test_tick_after_silence_returns_fail_safe_frames() -> None:
    s = gl.GazeStream(preset="paper", mode="range", timeout_ms=100)
    frames = fixations(s, 0.1)
    # Frames at 0 (no gaze yet: fail-safe) and 0.05, 0.1 (adaptive).
    assert [f.state for f in frames] == ["fail_safe", "adaptive", "adaptive"]
    assert frames[1].gaze_deg == 90.0 and frames[1].profile.gaze_deg == 90.0
    # The tracker goes silent; the LiDAR's frame clock keeps ticking.
    later = []
    for k in range(1, 11):
        later += s.tick(0.1 + k * 0.05)
    assert [round(f.t_s, 9) for f in later] == [round(0.15 + 0.05 * k, 9) for k in range(10)]
    states = [f.state for f in later]
    # The fixation at 0.1 s is 50 ms old at 0.15 and 100 ms at 0.2 (not
    # older than the timeout): adaptive; from 0.25 s it is stale.
    assert states[:2] == ["adaptive", "adaptive"]
    assert set(states[2:]) == {"fail_safe"}
    baseline = gl.profile(mode="baseline", gaze_deg=None)
    for f in later[2:]:
        assert f.gaze_deg is None
        np.testing.assert_array_equal(f.profile.power_w, baseline.power_w)
        np.testing.assert_array_equal(f.profile.spin_start_rad_s, baseline.spin_start_rad_s)
    assert s.stats["fail_safe_frames"] == 1 + 8
    # Nothing is due twice: ticking the same time again gives no frame.
    assert s.tick(0.6) == []


def test_tick_is_the_frame_rule_of_a_late_sample() -> None:
    # Silence then one sample (the CLI's replay) gives the same frames as
    # ticking through the silence.
    a = gl.GazeStream()
    b = gl.GazeStream()
    fa = fixations(a, 0.1) + a.tick(0.4) + a.push(0.6, 90.0)
    fb = fixations(b, 0.1) + b.push(0.6, 90.0)
    assert [(f.t_s, f.state) for f in fa] == [(f.t_s, f.state) for f in fb]


def test_tracker_loss_is_fail_safe_at_the_next_frame_and_recovery_needs_samples() -> None:
    s = gl.GazeStream(timeout_ms=100)
    fixations(s, 0.1)
    frames = s.push(0.105, 0.0, valid=False)  # eyes lost
    frames += s.push(0.15, 90.0)  # one good sample is not enough to recover
    assert frames[-1].state == "fail_safe"
    for k in range(1, 8):
        frames += s.push(0.15 + k * 0.005, 90.0)
    frames += s.push(0.2, 90.0)
    assert frames[-1].state == "adaptive"  # type: ignore[comparison-overlap]  # mypy keeps the earlier narrowing
    assert s.stats["invalid"] == 1


def test_a_clock_jump_resynchronizes_with_one_fail_safe_frame() -> None:
    s = gl.GazeStream()
    fixations(s, 0.1)
    frames = s.push(1e6, 90.0)
    assert [f.state for f in frames] == ["fail_safe"]
    assert s.stats["resyncs"] == 1
    (note,) = s.notices()
    assert "jumped" in note
    assert s.notices() == []


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="timeout_ms"):
        gl.GazeStream(timeout_ms=0)
    with pytest.raises(ValueError, match="mode"):
        gl.GazeStream(mode="fast")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="preset"):
        gl.GazeStream(preset="nope")
    with pytest.raises(ValueError, match="^recover_samples"):
        gl.GazeStream(recover_samples=-1)
    with pytest.raises(ValueError, match="^max_gap_frames"):
        gl.GazeStream(max_gap_frames=-1)
    s = gl.GazeStream()
    with pytest.raises(ValueError, match="t_s"):
        s.push(float("nan"), 90.0)
    with pytest.raises(ValueError, match="now_s"):
        s.tick(float("inf"))


def test_settings_take_the_cli_ranges() -> None:
    # One range check for the CLI's options and these keywords
    # (pipeline::PipelineOptions), so the same words as `gaze-lidar stream`.
    with pytest.raises(ValueError, match=r"^recover_samples: 0 must lie in 1\.\.=100000$"):
        gl.GazeStream(recover_samples=0)
    with pytest.raises(ValueError, match=r"^saccade_deg_s: 1000000 must be finite"):
        gl.GazeStream(saccade_deg_s=1e6)
    with pytest.raises(ValueError, match=r"^timeout_ms: 5e-324 must be finite \(not subnormal\)"):
        gl.GazeStream(timeout_ms=5e-324)
    gl.GazeStream(timeout_ms=1e-3, recover_samples=100_000, max_gap_frames=1_000_000)


def test_optimizer_stream(repo: pathlib.Path) -> None:
    cfg = (repo / "examples/configs/paper.toml").read_text()
    s = gl.GazeStream(mode="joint", config_toml=cfg)
    frames = fixations(s, 0.1)
    assert frames[-1].state == "adaptive"
    assert gl.check(frames[-1].profile.to_json()).certified


def test_same_frames_as_the_cli_stream(repo: pathlib.Path) -> None:
    """The CLI's `stream` (replay) on the same samples: the same frame times
    and states, and tick() through the silence changes nothing."""
    import json
    import shutil
    import subprocess

    cli = repo / "target/release/gaze-lidar"
    if not cli.exists():
        found = shutil.which("gaze-lidar")
        if found is None:
            pytest.skip("the gaze-lidar binary is not built (cargo build --release)")
        cli = pathlib.Path(found)
    samples = [(k / 200, 90.0, True) for k in range(21)] + [(0.12, 0.0, False)]
    samples += [(0.13 + k / 200, 270.0, True) for k in range(10)] + [(0.6, 270.0, True)]
    text = "".join(json.dumps({"t_s": t, "gaze_deg": g, "valid": v}) + "\n" for t, g, v in samples)
    out = subprocess.run(
        [str(cli), "stream", "--preset", "paper", "--mode", "range", "--timeout-ms", "100"],
        input=text, capture_output=True, text=True, check=True,
    ).stdout
    want = [(round(f["t_s"], 9), f["state"], f["gaze_deg"]) for f in map(json.loads, out.splitlines())]
    s = gl.GazeStream(preset="paper", mode="range", timeout_ms=100)
    got = []
    for t, g, v in samples[:-1]:
        got += s.push(t, g, v)
    got += s.tick(0.45)
    got += s.push(*samples[-1])
    assert [(round(f.t_s, 9), f.state, f.gaze_deg) for f in got] == want
    assert {f[1] for f in want} == {"adaptive", "fail_safe"}


def test_stream_certifies_the_head() -> None:
    # Every frame a head's stream hands out went through the checker, which
    # evaluates the whole head: its JSON re-checks certified for the head.
    s = gl.GazeStream(preset="vlp16", mode="range", timeout_ms=100)
    frames = fixations(s, 0.3)
    assert any(f.state == "adaptive" for f in frames)
    for f in frames:
        v = gl.check(f.profile.to_json(), preset="vlp16")
        assert v.certified and v.head_channels == 16
