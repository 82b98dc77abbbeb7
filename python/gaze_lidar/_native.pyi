"""Type stubs of gaze_lidar's native module (the Rust crates via pyo3).

Conventions: angles in degrees in the vehicle frame ISO 8855 (x forward,
y left, z up), azimuth counter-clockwise from straight ahead in [0, 360);
SI units elsewhere, the unit in each name. Errors: ValueError for bad input
(the message starts with the argument or field), Infeasible for a request
that cannot be met, Rejected for a profile that fails the checker.
"""

from os import PathLike
from typing import Any, Literal, Sequence

from typing_extensions import Self, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "Frame",
    "GAZE_FORMATS",
    "GazeStream",
    "Infeasible",
    "InternalError",
    "PRESETS",
    "Profile",
    "Rejected",
    "Verdict",
    "__version__",
    "apply_profile",
    "azimuth_deg",
    "check",
    "optimize",
    "profile",
    "read_gaze",
    "replay",
    "simulate",
]
__version__: str
"""The package version (the Rust crate's)."""

PRESETS: list[str]
"""Preset names accepted by `preset=` ("paper", "vls128", "vlp16", "os1-128")."""

GAZE_FORMATS: list[str]
"""The formats read_gaze reads, as `gaze-lidar stream --format` names them."""

class Infeasible(Exception):
    """The request is well-formed but cannot be met; the message names the limit."""

class InternalError(RuntimeError):
    """A bug in gaze-lidar: a Rust panic caught at the binding's edge."""

class Rejected(Exception):
    """A profile failed the checker.

    violations: every violated limit, one line each (as `gaze-lidar check`).
    """

    violations: list[str]

@final
class Profile:
    """A certified scan profile (`gaze-lidar/profile@1`).

    Every Profile has passed the checker against its declared limits
    (power budget, frame period, power and spin bounds, motor acceleration,
    power slew, Class 1 eye safety). Arrays are read-only float64, one
    entry per bin, bins in azimuth order tiling [0, 360). Immutable:
    compares and hashes by value (its profile@1 JSON), pickles and
    deep-copies through that JSON and its preset. Profile(text) is
    Profile.from_json(text); Profile(text, preset) also names the preset
    whose sensor and driver model give its `figures`.
    """

    def __new__(cls, text: str, preset: str | None = None) -> Profile: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __reduce__(self) -> tuple[type[Profile], tuple[str, str | None]]: ...
    def __copy__(self) -> Self: ...
    def __deepcopy__(self, _memo: Any) -> Profile: ...
    def power_w_at(self, azimuth_deg: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Laser power at each azimuth (degrees, any shape, wrapped into [0, 360)), W."""
    def spin_rad_s_at(self, azimuth_deg: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Head spin at each azimuth (degrees, any shape, wrapped into [0, 360)), rad/s."""

    @property
    def start_deg(self) -> npt.NDArray[np.float64]:
        """Bin start azimuths, degrees."""
    @property
    def width_deg(self) -> npt.NDArray[np.float64]:
        """Bin widths, degrees (sum 360)."""
    @property
    def power_w(self) -> npt.NDArray[np.float64]:
        """Laser power per bin (mean optical output while scanning it), W."""
    @property
    def spin_start_rad_s(self) -> npt.NDArray[np.float64]:
        """Spin at each bin's start, rad/s."""
    @property
    def spin_end_rad_s(self) -> npt.NDArray[np.float64]:
        """Spin at each bin's end, rad/s (constant angular acceleration within a bin)."""
    @property
    def dwell_s(self) -> npt.NDArray[np.float64]:
        """Time spent in each bin, s (sums to the frame period)."""
    @property
    def in_rof(self) -> npt.NDArray[np.bool_]:
        """Whether each bin lies in the driver's region of focus."""
    @property
    def gaze_deg(self) -> float | None:
        """The gaze azimuth the profile was built for; None for the uniform baseline."""
    @property
    def mode(self) -> str | None:
        """How it was made, e.g. "closed-form range" or "optimized joint"."""
    @property
    def frame_rate_hz(self) -> float:
        """Nominal revolutions per second."""
    @property
    def pulse_rate_hz(self) -> float:
        """Laser firing rate per channel, Hz."""
    @property
    def average_power_w(self) -> float:
        """The average power budget P̄, W."""
    @property
    def power_accounting(self) -> Literal["time", "angle"]:
        """How the budget is averaged: over time (energy per frame) or over angle (eq. 4)."""
    @property
    def limits(self) -> dict[str, Any]:
        """The declared limits (profile@1 `limits`)."""
    @property
    def summary(self) -> dict[str, Any]:
        """The checker's figures: average_power_angle_w, average_power_time_w,
        energy_per_frame_j, frame_period_s, max_spin_accel_rad_s2 (None for a
        spin step), rof_width_deg, power_w_range, spin_rad_s_range."""
    @property
    def optimality(self) -> dict[str, Any] | None:
        """The optimizer's figures (profile@1 `optimality`): objective,
        upper_bound, gap, exact, global, figures, dwell_step (the dwell
        steps' programs: the last one's exact figures and how many ran), and
        eye_safety_tightening when the power step had to tighten its
        eye-safety cuts; None for the closed forms."""
    @property
    def preset(self) -> str | None:
        """The preset it was planned on (closed forms, closed-form stream
        frames); None when unknown (optimizer output, JSON read alone)."""
    @property
    def figures(self) -> dict[str, Any] | None:
        """Range and point density in units people use (profile@1
        `optimality.figures`): {"profile": {"rof", "roi"}, "closed_form":
        {"rof", "roi"} or absent, "closed_form_rejected": reason or absent};
        each region {"width_deg", "range_m", "points_per_deg"} (None when no
        bin lies in it), each figure {"mean" (angle-weighted over the
        region's bins), "min", "max"}. Range on the reference reflectivity in
        clear air (MOR 20 km) from the range equation at the sensor's rated
        range; points per degree per channel and revolution. A closed form
        (a profile that knows its `preset`) has {"profile"} only; None for a
        profile with neither (JSON read without a preset)."""
    def to_dict(self) -> dict[str, npt.NDArray[Any]]:
        """The bins as numpy columns: start_deg, width_deg, power_w,
        spin_start_rad_s, spin_end_rad_s, dwell_s, in_rof, and, when the
        preset is known, range_m and points_per_deg per bin."""
    def to_pandas(self) -> Any:
        """to_dict() as a pandas.DataFrame, one row per bin (ImportError
        naming pandas when it is not installed)."""
    def to_json(self) -> str:
        """The profile as `gaze-lidar/profile@1` JSON (what `gaze-lidar check` reads)."""
    @staticmethod
    def from_json(text: str) -> Profile:
        """Parses profile@1 JSON and certifies it against its declared limits.

        Raises ValueError for malformed JSON (line:column and field named)
        and Rejected when a limit is violated.
        """
    def firmware(self, tick_hz: int = 80_000_000, power_w_per_code: float | None = None) -> dict[str, Any]:
        """Integer firmware tables (`gaze-lidar/firmware@1`), conservatively rounded.

        Scalars: format, tick_hz, frame_ticks, power_w_per_code,
        power_accounting, pulse_rate_hz, limits (dict), eye_safety (dict or
        None). numpy arrays, one entry per bin: start_deg (float64),
        width_mdeg (uint32), dwell_ticks (uint64, summing to frame_ticks),
        power_code (uint32), dwell_ticks_min, dwell_ticks_max (uint64),
        power_code_cap (uint32). power_w_per_code defaults to
        limits.power_w_max / 4095.
        """
    def firmware_json(self, tick_hz: int = 80_000_000, power_w_per_code: float | None = None) -> str:
        """The firmware table as `gaze-lidar/firmware@1` JSON."""
    def __len__(self) -> int:
        """Number of bins."""

def profile(
    preset: str = "paper",
    mode: Literal["baseline", "range", "resolution", "joint"] = "range",
    gaze_deg: float | None = 90.0,
    bins: int = 360,
    accounting: Literal["time", "angle"] | None = None,
) -> Profile:
    """The paper's closed-form controller (eq. 3–6), certified.

    mode "baseline" ignores gaze_deg (the uniform, fail-safe profile); the
    others need it. bins: 4..=36000 equal bins (region boundaries are added
    as edges). accounting overrides the preset's power accounting.
    Raises ValueError (e.g. "gaze_deg: NaN is not a finite azimuth …"),
    Infeasible, or Rejected (e.g. a spin step on a motor with an
    acceleration limit).
    """

def optimize(config_text: str, gaze_deg: float, json: bool = False) -> Profile:
    """The optimizer's certified profile (HiGHS) for a TOML
    configuration as `gaze-lidar profile --config` reads it (see
    examples/configs/). Releases the GIL while solving.
    Raises ValueError for a bad key (named), Infeasible naming the limit."""

@final
class Verdict:
    """The checker's verdict on a profile@1 file. Truthy when certified."""

    certified: bool
    violations: list[str]
    """One line per violated limit, as `gaze-lidar check` prints them."""
    limits: list[str]
    """The profile@1 key each violation is about (e.g. "power_w_max", "eye_safety")."""
    worst_ratio: float | None
    """Worst eye-safety exposure / Class 1 limit (> 1 fails); None when not evaluated."""
    binding_rule: str | None
    """The IEC 60825-1 rule that binds at the worst azimuth."""
    worst_azimuth_deg: float | None
    """Azimuth of the worst eye-safety exposure."""
    head_channels: int | None
    """Channels of the head eye safety was evaluated for; None for one channel (no head given) or when not evaluated."""
    power_scale_to_certify: float | None
    """The largest uniform power scale (every bin power times it) at which eye safety certifies; None when not evaluated."""
    def __new__(
        cls,
        certified: bool,
        violations: list[str],
        limits: list[str],
        worst_ratio: float | None = None,
        binding_rule: str | None = None,
        worst_azimuth_deg: float | None = None,
        head_channels: int | None = None,
        power_scale_to_certify: float | None = None,
    ) -> Verdict:
        """A verdict from its fields (what pickle calls; check() makes them)."""
    def __reduce__(
        self,
    ) -> tuple[
        type[Verdict],
        tuple[bool, list[str], list[str], float | None, str | None, float | None, int | None, float | None],
    ]: ...
    def __eq__(self, other: object, /) -> bool: ...
    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict."""
    def to_pandas(self) -> Any:
        """A pandas.DataFrame, one row per violation (limit, violation and
        the scalars; one row for a certified verdict). Needs pandas."""
    def __bool__(self) -> bool: ...

def check(profile_json: str, preset: str | None = None, *, no_eye_safety: bool = False) -> Verdict:
    """Verifies profile@1 JSON against its declared limits; with preset, also
    against that sensor (a declared limit looser than the sensor's is a
    violation). A file without eye-safety parameters is rejected unless
    no_eye_safety=True. Raises ValueError when the JSON does not parse.
    Ctrl-C returns at once (KeyboardInterrupt)."""

@final
class Frame:
    """One LiDAR frame of a GazeStream. Pickles; equal when t_s, state and
    the profile are."""

    t_s: float
    """Frame start on the gaze clock, s."""
    state: Literal["adaptive", "fail_safe"]
    def __new__(cls, t_s: float, state: Literal["adaptive", "fail_safe"], profile: Profile) -> Frame:
        """A frame from its fields (what pickle calls; streams make them)."""
    def __reduce__(self) -> tuple[type[Frame], tuple[float, str, Profile]]: ...
    def __eq__(self, other: object, /) -> bool: ...
    def to_dict(self) -> dict[str, Any]:
        """t_s, state, gaze_deg and the profile's mode."""
    def to_pandas(self) -> Any:
        """The frame's profile as a pandas.DataFrame, one row per bin
        (Profile.to_pandas), with t_s, state and gaze_deg on every row."""
    @property
    def profile(self) -> Profile:
        """The certified profile the LiDAR runs during this frame."""
    @property
    def gaze_deg(self) -> float | None:
        """The gaze the profile was built for; None in fail-safe."""

@final
class GazeStream:
    """Gaze samples in, one certified profile per LiDAR frame out.

    The frame clock drives the fail-safe (the CLI's `stream` rules): frame k
    starts at t0 + k·T (t0 the first sample or tick, T the frame period);
    a frame is adaptive only if the newest fixation is no older than
    timeout_ms when it is decided, and after a loss only once
    recover_samples consecutive valid samples arrived; otherwise it runs the
    uniform baseline. A timestamp jump of more than max_gap_frames periods
    emits one fail-safe frame and restarts the clock. The settings take the
    ranges of the CLI's options: timeout_ms in (0, 1e7), rounded to a
    microsecond; recover_samples 1..=100000; saccade_deg_s in (0, 1e6);
    max_gap_frames 0..=1000000.

    With config_toml, frames are planned by the optimizer's fast path
    (mode overrides the objective); otherwise by the preset's closed form.
    """

    def __new__(
        cls,
        preset: str = "paper",
        mode: Literal["range", "resolution", "joint", "baseline"] = "range",
        timeout_ms: float = 100.0,
        *,
        bins: int = 360,
        recover_samples: int = 4,
        saccade_deg_s: float = 30.0,
        max_gap_frames: int = 200,
        config_toml: str | None = None,
    ) -> GazeStream: ...
    def push(self, t_s: float, gaze_deg: float, valid: bool = True) -> list[Frame]:
        """Feeds one tracker sample (gaze clock t_s); returns the frames that
        start at or before it, each decided from the samples before it.
        valid=False (or a non-finite gaze) means the tracker lost the eyes."""
    def push_many(
        self,
        t_s: npt.ArrayLike,
        gaze_deg: npt.ArrayLike,
        valid: npt.ArrayLike | None = None,
    ) -> list[Frame]:
        """Feeds a recorded gaze track (1-D arrays of one length) in order, as
        many push calls would; returns all the frames they emit.

        t_s and gaze_deg: real numbers (numpy dtype kinds f, i, u; a
        NaN gaze is an invalid sample, a non-finite time an error); valid:
        booleans (dtype bool) or None for all valid. Anything else (dates,
        timedeltas, strings, objects such as a pandas "boolean" column with
        NA, floats for valid) raises ValueError naming the argument."""
    def tick(self, now_s: float) -> list[Frame]:
        """Runs the frame clock to now_s without a sample: the frames due by
        then, fail-safe once the last fixation is older than the timeout.
        Call it on each LiDAR frame so silence still yields frames."""
    @property
    def period_s(self) -> float:
        """The frame period on the frame clock (rounded to a microsecond), s."""
    @property
    def stats(self) -> dict[str, int]:
        """samples, invalid, outliers, frames, fail_safe_frames, resyncs, plan_fallbacks."""
    def notices(self) -> list[str]:
        """Warnings since the last call (clock jumps, planning fallbacks), one line each."""

def apply_profile(
    profile: Profile,
    points: npt.NDArray[np.float32] | npt.NDArray[np.float64],
    *,
    rated_range_m: float,
    model: Literal["physical", "argus"] = "physical",
    fog_mor_m: float | None = None,
    seed: int = 0,
    frame: Literal["carla", "iso8855"] = "carla",
    cloud_spin_rad_s: float | None = None,
) -> npt.NDArray[np.bool_]:
    """Which points a sensor running `profile` would return: a bool mask.

    points: N x 4 float32 in CARLA's layout (x, y, z, intensity; sensor
    frame, metres); N x 3 and float64 are accepted too. Azimuth: the crate's
    convention; with frame="carla" (x forward, y right, z up: left-handed)
    it is atan2(-y, x), with frame="iso8855" (y left) atan2(y, x).

    Range: a point at distance sqrt(x²+y²+z²) is kept if the profile's power
    at its azimuth, P(β)/P̄, detects a normal-incidence target of the
    reference reflectivity there with P_D ≥ ½ — the simulator's return
    model: "physical" (range equation calibrated so the uniform baseline
    reaches rated_range_m in clear air; fog as extinction 2.996/fog_mor_m)
    or "argus" (the paper code's intensity model: hard 100 m; fog_mor_m only
    None, 200 or 100, the paper's levels). The intensity column is not used.

    Density: relative to the spin the cloud was recorded at
    (cloud_spin_rad_s, default the uniform 2π·frame_rate_hz), a point at
    azimuth β survives with probability min(1, ω_cloud/ω(β)), from seeded
    draws (one per point, in order): same seed, same mask.

    Vectorized in Rust (no Python loop); the GIL is released for contiguous
    float32 input.
    """

def azimuth_deg(
    points: npt.NDArray[np.float32] | npt.NDArray[np.float64],
    frame: Literal["carla", "iso8855"] = "carla",
) -> npt.NDArray[np.float64]:
    """Azimuth of each point in the crate's convention, degrees in [0, 360),
    exactly as apply_profile maps the frame (atan2(-y, x) for CARLA)."""

def read_gaze(path: str, format: str = "jsonl") -> dict[str, npt.NDArray[Any]]:
    """A recorded gaze file by the CLI's parsers: {"t_s", "gaze_deg", "valid"} as numpy columns."""

def simulate(
    model: Literal["argus", "physical"] | Sequence[str] = "argus",
    trials: int = 10,
    seed: int = 1,
    **options: Any,
) -> dict[str, Any]:
    """The paper's T-intersection experiment (`gaze-lidar simulate`):
    {"rows": one dict per model × variant × fog level (model, variant,
    fog_pct, trials, detected, tta_median_s, tta_q1_s, tta_q3_s,
    density_median_pts_per_deg, density_median_pts_per_deg_s,
    left_tta_median_s, left_detected, hybrid_tta_median_s,
    left_hybrid_tta_median_s), "trials_csv": the CLI's --trials-csv text}.
    Same seed, same rows. Runs on a thread pool of its own (fork-safe) and
    stops at Ctrl-C (KeyboardInterrupt).

    options: variants (list of "baseline", "range", "resolution", "joint",
    "optimized"), fog_pct (list of 0, 25, 50), detect ("k/n"), bins,
    preset, scenario_toml (TOML text), optimizer_toml (TOML text, with the
    "optimized" variant; the closed-form variants then run on its sensor,
    limits and driver model, with the levels of the preset it names, which
    preset replaces, as the CLI's --optimizer-config). Releases the GIL while it runs.
    """

def replay(
    in_path: str | PathLike[str],
    out_path: str | PathLike[str],
    *,
    gaze_topic: str,
    cloud_topic: str,
    preset: str = "paper",
    mode: Literal["baseline", "range", "resolution", "joint"] = "range",
    bins: int = 360,
    config_toml: str | None = None,
    gaze_yaw_deg: bool = False,
    sensor_yaw_deg: float | None = None,
    vehicle_frame: str = "base_link",
    tf_topic: str = "/tf_static",
    max_mount_tilt_deg: float = 5.0,
    rated_range_m: float | None = None,
    model: Literal["physical", "argus"] = "physical",
    fog_mor_m: float | None = None,
    seed: int = 0,
    cloud_spin_rad_s: float | None = None,
    timeout_ms: float = 100.0,
    recover_samples: int = 4,
    saccade_deg_s: float = 30.0,
    max_gap_frames: int = 200,
    reorder_window_ms: float = 200.0,
    adapted_topic: str | None = None,
    profile_topic: str = "/gaze_lidar/profile",
    scene_topic: str = "/gaze_lidar/scene",
    compression: Literal["none", "lz4", "zstd"] = "none",
) -> dict[str, int]:
    """Replays the ROS 2 bag (MCAP) at in_path through the gaze pipeline
    and writes out_path, as `gaze-lidar replay` does (same Rust code, same
    options): every input message copied, one adapted cloud per cloud on
    adapted_topic (default cloud_topic + "/adapted"), one profile@1 document
    per frame on profile_topic (std_msgs/msg/String) and a
    visualization_msgs/msg/MarkerArray per frame on scene_topic. out_path is replaced only when the replay succeeds.
    Returns the counters (messages, clouds, points_in, points_kept,
    late_clouds, late_gaze, clouds_without_tf, transforms, attachments,
    metadata, plan_fallbacks (frames that ran the baseline because no
    adaptive profile certified), resyncs (gaze clock jumps), samples,
    invalid, outliers, frames, fail_safe_frames). Input messages keep
    their sequence numbers; attachments and metadata records are copied.
    bins: 4..=1440 (each frame's profile is written out).

    The mounting yaw: sensor_yaw_deg when given, else the bag's static
    transforms on tf_topic from the cloud's header.frame_id to
    vehicle_frame. ValueError for a bad option or bag (naming the field or
    the byte offset), Infeasible for a request the planner cannot meet,
    OSError when out_path cannot be written. Releases the GIL.
    """
