"""Simulation results as records: rows, per-trial records, dicts, DataFrames.

pandas is optional: only ``to_pandas`` imports it, and says how to get it
when it is missing.
"""

from __future__ import annotations

import csv
import importlib
import io
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, List, Dict, Literal

if TYPE_CHECKING:
    from ._native import Frame

#: A ``pandas.DataFrame`` (typed loosely: pandas is optional).
DataFrame = Any


def _pandas(what: str) -> Any:
    # import_module, not `import pandas`: type-checking this package must
    # not need pandas' stubs.
    try:
        return importlib.import_module("pandas")
    except ImportError:
        raise ImportError(
            f"{what} needs pandas, which is not installed: `pip install pandas` "
            "(to_dict() gives the same data without it)"
        ) from None


def _value(text: str) -> bool | int | float | str | None:
    """One CSV field: empty → None, `true`/`false` → a bool, an integer, a
    float (the CLI writes the shortest text that reads back to the same
    float), else the text."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def parse_trials_csv(text: str) -> list[dict[str, Any]]:
    """The CLI's ``--trials-csv`` records, one dict per trial, typed."""
    return [{k: _value(v) for k, v in row.items()} for row in csv.DictReader(io.StringIO(text))]


class SimulationResult(List[Dict[str, Any]]):
    """What :func:`gaze_lidar.simulate` returns: the table's rows (the list
    itself, one dict per model × variant × fog level, as before) and
    :attr:`trials`, one record per trial and cell — the same records, column
    for column, as ``gaze-lidar simulate --trials-csv`` writes: model,
    variant, fog_pct, trial, tta_right_s, tta_left_s, hybrid_right_s,
    hybrid_left_s (None where not detected before arrival), roi_points,
    roi_pulses, duration_s, density_pts_per_deg_s."""

    trials: list[dict[str, Any]]

    def __init__(self, rows: Iterable[dict[str, Any]], trials: Iterable[dict[str, Any]]) -> None:
        super().__init__(rows)
        self.trials = list(trials)

    def to_dict(self) -> dict[str, list[dict[str, Any]]]:
        """{"rows": [...], "trials": [...]} (plain lists of dicts)."""
        return {"rows": list(self), "trials": list(self.trials)}

    def to_pandas(self, what: Literal["rows", "trials"] = "rows") -> DataFrame:
        """The rows (one per cell) or, with ``what="trials"``, the per-trial
        records as a DataFrame. Needs pandas."""
        pd = _pandas("SimulationResult.to_pandas")
        if what == "rows":
            return pd.DataFrame(list(self))
        if what == "trials":
            return pd.DataFrame(self.trials)
        raise ValueError(f"what: {what!r} is not one of 'rows', 'trials'")

    def __reduce__(self) -> tuple[Any, ...]:
        return (SimulationResult, (list(self), self.trials))


def frames_to_pandas(frames: Iterable[Frame]) -> DataFrame:
    """One row per frame (``Frame.to_dict()``: t_s, state, gaze_deg, mode).
    Needs pandas."""
    pd = _pandas("frames_to_pandas")
    return pd.DataFrame([f.to_dict() for f in frames], columns=["t_s", "state", "gaze_deg", "mode"])
