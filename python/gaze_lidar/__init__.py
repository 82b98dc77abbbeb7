"""gaze-lidar: certified gaze-aware LiDAR scan schedules, from Python.

The physics, the checker and the gaze pipeline are the Rust crates
``gaze-lidar`` and ``gaze-lidar-core``; this package is their Python face
(pyo3 + numpy). Every profile it hands out has passed the checker.

Angles follow the crate: vehicle frame ISO 8855 (x forward, y left, z up),
azimuth in degrees counter-clockwise from straight ahead in [0, 360); a gaze
of 90 degrees looks left, and an adaptive profile then favours the side the
driver is *not* watching (more range or resolution away from the gaze).
CARLA's sensor frame is left-handed (x forward, y right, z up): an azimuth
there is ``atan2(-y, x)``, which :func:`apply_profile` does for
``frame="carla"`` (the default). :mod:`gaze_lidar.carla` reads CARLA's
measurements and checks a LiDAR blueprint.

Point clouds: any array numpy can view as real numbers, N×3 or N×4 (x, y,
z[, intensity]) in any dtype, byte order, memory order or strides, a
structured array with x/y/z fields, or a raw CARLA byte buffer (see
``gaze_lidar._points``). The per-point loops run in Rust with the GIL
released. Every object may be used from any thread (``GazeStream`` has an
internal lock).

Errors: ``ValueError`` for bad input (the message names the argument or
field), :class:`Infeasible` for a request that cannot be met (it names the
limit), :class:`Rejected` for a profile that fails the checker (its
``violations`` attribute lists every violated limit), :class:`InternalError`
(a ``RuntimeError``) for a bug caught at the Rust edge.

Processes and signals: long calls (:func:`simulate`, :func:`check`,
:func:`optimize`) check for signals every 50 ms, so Ctrl-C (a
``KeyboardInterrupt``) stops them at once (``simulate`` starts no further
trial, its threads left parked, idle, until the process exits; ``check``
and ``optimize`` return at once and let the checker or solver finish in the
background). Parallel work runs on a thread pool made for the
call, never a global one, so a process ``fork``ed after a call (the default
start method of ``multiprocessing`` on Linux up to Python 3.13) can call
anything again. :class:`Profile`, :class:`Frame`, :class:`Verdict` and the
results of :func:`simulate` pickle (and compare equal after the round trip).

Terms (as the code uses them):

- *rated range*: the distance at which the sensor's uniform (baseline)
  profile, at its average power P̄, detects a target of the reference
  reflectivity at normal incidence with probability ½, in clear air.
- *reference reflectivity*: the diffuse (Lambertian) reflectivity the
  sensor's range is rated on, the preset's (10 % for every preset).
- *clear air*: a meteorological optical range (MOR) of 20 km, i.e. an
  extinction of 2.996 / 20 km (``gaze_lidar::model::range::CLEAR_AIR_MOR_M``);
  the simulator's fog 0 % level.
- *fog* (``fog_pct`` 0, 25, 50: the paper's labels): MORs of 20 km (clear
  air), 200 m and 100 m (the ARGUS code's fog_density 0, 50 and 100);
  extinction α = 2.996 / MOR.
- *range* of a bin: the distance R at which a pulse of the bin's power P
  still detects the reference reflectivity in clear air: the range
  equation ``(P/P̄)·(R₀/R)²·e^(−2α₀(R−R₀)) = 1`` (R₀ the rated range, α₀ =
  2.996 / 20 km), close to ``R₀·√(P/P̄)``.
- *points per degree*: per channel and revolution, the pulse rate times the
  bin's dwell time over its width.
- *region of focus* (RoF, ``in_rof``): the azimuths the driver covers
  around the gaze (the preset's driver model); *region of interest* (RoI):
  the rest of the circle, where an adaptive profile puts its range or
  density.
- *TTA* (time to arrival): seconds left before the crossing car reaches
  the ego lane when it is first detected; larger is earlier.
- *fail-safe*: the uniform baseline profile, run whenever gaze is stale.
"""

from __future__ import annotations

import json
import os
import secrets
from collections.abc import Mapping, Sequence
from typing import Any, Literal, Union

import numpy as np
import numpy.typing as npt

from . import _native
from ._native import (
    PRESETS,
    Frame,
    GazeStream,
    Infeasible,
    InternalError,
    Profile,
    Rejected,
    Verdict,
    __version__,
    profile,
    replay,
)
from ._points import as_points, rotate_yaw
from ._results import SimulationResult, frames_to_pandas, parse_trials_csv

#: The formats :func:`read_gaze` reads (``gaze-lidar stream --format``).
GAZE_FORMATS: list[str] = list(_native.GAZE_FORMATS)

#: What :func:`check` accepts: a Profile, a profile@1 dict, a path, or JSON text.
ProfileSource = Union[Profile, Mapping[str, Any], os.PathLike[str], str]
#: What :func:`optimize` accepts: a dict, a path (.toml or .json), or TOML text.
ConfigSource = Union[Mapping[str, Any], os.PathLike[str], str]


def _fresh_seed(seed: int | None) -> int:
    """`seed`, or fresh entropy (64 bits from the OS) for None, as numpy does."""
    if seed is None:
        return secrets.randbits(64)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ValueError(f"seed: {seed!r} is not an integer or None")
    return int(seed)


def _read(path: os.PathLike[str] | str, name: str) -> str:
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        raise ValueError(f"{name}: {os.fspath(path)}: {e.strerror or e}") from None


def check(
    profile: ProfileSource, preset: str | None = None, *, no_eye_safety: bool = False
) -> Verdict:
    """Verifies a profile against its declared limits; with `preset`, also
    against that sensor (a declared limit looser than the sensor's is a
    violation). A file without eye-safety parameters is rejected unless
    ``no_eye_safety=True``.

    `profile`: a :class:`Profile`, a profile@1 dict (as ``json.loads``
    gives), a path (``str`` or ``os.PathLike``) to a profile@1 file, or the
    JSON text itself (a ``str`` starting with ``{``). Raises ValueError when
    it does not parse (line:column and field named) or the file cannot be read.
    """
    if isinstance(profile, Profile):
        text = profile.to_json()
    elif isinstance(profile, Mapping):
        text = json.dumps(profile)
    elif isinstance(profile, os.PathLike):
        text = _read(profile, "profile")
    elif isinstance(profile, str):
        text = profile if profile.lstrip().startswith("{") else _read(profile, "profile")
    else:
        raise ValueError(
            f"profile: expected a Profile, dict, path or JSON text, got {type(profile).__name__}"
        )
    return _native.check(text, preset, no_eye_safety=no_eye_safety)


def optimize(config: ConfigSource, gaze_deg: float) -> Profile:
    """The optimizer's certified profile (HiGHS) for a
    configuration as ``gaze-lidar profile --config`` reads it (see
    examples/configs/), for a driver looking at `gaze_deg` (degrees, ISO
    8855). Releases the GIL while solving.

    `config`: a dict of the same keys, a path to a ``.toml`` (or ``.json``)
    file, or TOML text (a ``str`` that names no existing file). Raises
    ValueError for a bad key (named), Infeasible naming the limit.

    The profile's ``optimality`` dict holds the exact gap of the final power
    step and, in ``figures`` (also ``Profile.figures``), the range in metres
    and the points per degree inside and outside the region of focus next to
    the paper's closed form's for the same gaze.
    """
    if isinstance(config, Mapping):
        return _native.optimize(json.dumps(config), gaze_deg, json=True)
    if isinstance(config, os.PathLike) or (
        isinstance(config, str) and "\n" not in config and os.path.isfile(config)
    ):
        text = _read(config, "config")
        is_json = os.fspath(config).lower().endswith(".json")
        return _native.optimize(text, gaze_deg, json=is_json)
    if isinstance(config, str):
        return _native.optimize(config, gaze_deg)
    raise ValueError(f"config: expected a dict, path or TOML text, got {type(config).__name__}")


def azimuth_deg(
    points: Any,
    frame: Literal["carla", "iso8855"] = "carla",
    *,
    sensor_yaw_deg: float = 0.0,
) -> npt.NDArray[np.float64]:
    """Azimuth of each point in the crate's convention, degrees in [0, 360):
    ``atan2(-y, x)`` for ``frame="carla"`` (x forward, y right),
    ``atan2(y, x)`` for ``"iso8855"`` (y left), plus `sensor_yaw_deg` (the
    sensor's x axis, degrees counter-clockwise from the vehicle's) — exactly
    as :func:`apply_profile` maps a point. `points`: any layout (see the
    module docs)."""
    pts = as_points(points)
    if sensor_yaw_deg != 0.0:
        return _native.azimuth_deg(rotate_yaw(pts, frame, sensor_yaw_deg), "iso8855")
    return _native.azimuth_deg(pts, frame)


def apply_profile(
    profile: Profile,
    points: Any,
    *,
    rated_range_m: float,
    model: Literal["physical", "argus"] = "physical",
    fog_mor_m: float | None = None,
    seed: int | None = 0,
    frame: Literal["carla", "iso8855"] = "carla",
    cloud_spin_rad_s: float | None = None,
    sensor_yaw_deg: float = 0.0,
) -> npt.NDArray[np.bool_]:
    """Which points a sensor running `profile` would return: a bool mask.

    points: N x 4 (x, y, z, intensity; sensor frame, metres) as CARLA gives
    them, or any layout numpy can view as real numbers (see the module
    docs): N x 3, any dtype, byte order, memory order or strides, a
    structured x/y/z array, a raw CARLA buffer. Azimuth: the crate's
    convention; with frame="carla" (x forward, y right, z up: left-handed)
    it is atan2(-y, x), with frame="iso8855" (y left) atan2(y, x);
    sensor_yaw_deg turns the sensor frame into the vehicle frame the profile
    is defined in (the sensor's x axis, degrees counter-clockwise from the
    vehicle's; a CARLA transform's yaw is clockwise: pass its negative, or
    use :func:`gaze_lidar.carla.apply_to_measurement`).

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
    draws (one per point, in order): same seed, same mask; seed=None draws
    a fresh seed from the OS.

    Vectorized in Rust (no Python loop), with the GIL released.
    """
    pts = as_points(points)
    if sensor_yaw_deg != 0.0:
        pts, frame = rotate_yaw(pts, frame, sensor_yaw_deg), "iso8855"
    return _native.apply_profile(
        profile,
        pts,
        rated_range_m=rated_range_m,
        model=model,
        fog_mor_m=fog_mor_m,
        seed=_fresh_seed(seed),
        frame=frame,
        cloud_spin_rad_s=cloud_spin_rad_s,
    )


def simulate(
    model: Literal["argus", "physical"] | Sequence[str] = "argus",
    trials: int = 10,
    seed: int | None = 1,
    **options: Any,
) -> SimulationResult:
    """The paper's T-intersection experiment (``gaze-lidar simulate``): one
    row per model × variant × fog level, as a dict (model, variant, fog_pct,
    trials, detected, tta_median_s, tta_q1_s, tta_q3_s,
    density_median_pts_per_deg, density_median_pts_per_deg_s,
    left_tta_median_s, left_detected, hybrid_tta_median_s,
    left_hybrid_tta_median_s). Same seed, same rows; seed=None draws a
    fresh seed from the OS.

    The result is a list of those rows (a :class:`SimulationResult`) whose
    ``trials`` holds one record per trial and cell, as ``--trials-csv``
    writes them; ``to_dict()`` and ``to_pandas()`` (``"rows"`` or
    ``"trials"``) give both.

    options: variants (list of "baseline", "range", "resolution", "joint",
    "optimized"), fog_pct (list of 0, 25, 50), detect ("k/n"), bins,
    preset, scenario_toml (TOML text), optimizer_toml (TOML text, with the
    "optimized" variant; the closed-form variants then run on its sensor,
    limits and driver model, with the levels of the preset it names, which
    preset replaces, as the CLI's --optimizer-config). Releases the GIL while it runs, runs on a thread
    pool of its own (fork-safe) and stops at Ctrl-C.
    """
    out = _native.simulate(model, trials, _fresh_seed(seed), **options)
    return SimulationResult(out["rows"], parse_trials_csv(out["trials_csv"]))


def read_gaze(
    path: os.PathLike[str] | str,
    format: Literal["jsonl", "csv", "varjo", "neon"] = "jsonl",
) -> dict[str, npt.NDArray[Any]]:
    """A recorded gaze file, read by the same parsers as ``gaze-lidar stream
    --input PATH --format FORMAT`` (the Rust ones; no second parser here):
    ``jsonl`` and ``csv`` (``t_s``, ``gaze_deg``, optional ``valid``), Varjo
    Base gaze CSV (``varjo``), Pupil Neon ``gaze.csv`` (``neon``); see
    :data:`GAZE_FORMATS`.

    Returns the samples as numpy columns: ``t_s`` (float64, s), ``gaze_deg``
    (float64, degrees, ISO 8855: 90 looks left) and ``valid`` (bool: the
    tracker had the eyes and the azimuth is usable) — the keyword arguments
    of :meth:`GazeStream.push_many` (``stream.push_many(**track)``), and
    ``pandas.DataFrame(track)`` tabulates them. A malformed line raises
    ValueError naming the file, the line and the field, as the CLI does.
    """
    return _native.read_gaze(os.fspath(path), format)


__all__ = [
    "GAZE_FORMATS",
    "PRESETS",
    "ConfigSource",
    "Frame",
    "GazeStream",
    "Infeasible",
    "InternalError",
    "Profile",
    "ProfileSource",
    "Rejected",
    "SimulationResult",
    "Verdict",
    "__version__",
    "apply_profile",
    "azimuth_deg",
    "carla",
    "check",
    "frames_to_pandas",
    "optimize",
    "profile",
    "read_gaze",
    "replay",
    "simulate",
]

# Last: gaze_lidar.carla imports from this module.
from . import carla  # noqa: E402

