"""gaze-lidar: certified gaze-aware LiDAR scan schedules, from Python.

The physics, the checker and the gaze pipeline are the Rust crates
``gaze-lidar`` and ``gaze-lidar-core``; this package is their Python face
(pyo3 + numpy). Every profile it hands out has passed the checker.

Angles follow the crate: vehicle frame ISO 8855 (x forward, y left, z up),
azimuth in degrees counter-clockwise from straight ahead in [0, 360); a gaze
of 90 degrees looks left. CARLA's sensor frame is left-handed (x forward,
y right, z up): an azimuth there is ``atan2(-y, x)``, which
:func:`apply_profile` does for ``frame="carla"`` (the default).

Errors: ``ValueError`` for bad input (the message names the argument or
field), :class:`Infeasible` for a request that cannot be met (it names the
limit), :class:`Rejected` for a profile that fails the checker (its
``violations`` attribute lists every violated limit).
"""

from ._native import (
    PRESETS,
    Frame,
    GazeStream,
    Infeasible,
    Profile,
    Rejected,
    Verdict,
    apply_profile,
    azimuth_deg,
    check,
    optimize,
    profile,
    simulate,
)

__all__ = [
    "PRESETS",
    "Frame",
    "GazeStream",
    "Infeasible",
    "Profile",
    "Rejected",
    "Verdict",
    "apply_profile",
    "azimuth_deg",
    "check",
    "optimize",
    "profile",
    "simulate",
]

