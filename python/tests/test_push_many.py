"""push_many's inputs (hypothesis): every dtype of `valid` and the times,
NaN, order and stride, pandas nullable columns.

The rule, written from the docs (``GazeStream.push_many``): times and
azimuths are real numbers (numpy dtype kinds f, i, u), `valid` is booleans
(kind b) or None; anything else raises ValueError naming the argument. An
accepted batch is exactly the pushes of its samples one by one, in order,
with each value as numpy converts it to float64 / bool.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import gaze_lidar as gl

SETTINGS = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])

REAL = "fiu"


def one_by_one(t: Any, g: Any, v: Any) -> tuple[list[tuple[float, str, float | None]], dict[str, int]] | str:
    """The reference: push per sample; the error's type and message if one is raised."""
    s = gl.GazeStream()
    ts = np.asarray(t).astype(np.float64)
    gs = np.asarray(g).astype(np.float64)
    vs = np.ones(ts.shape, dtype=bool) if v is None else np.asarray(v).astype(bool)
    if ts.ndim != 1 or not np.all(np.isfinite(ts)):
        return "ValueError"
    out = []
    try:
        for ti, gi, vi in zip(ts, gs, vs):
            out += s.push(float(ti), float(gi), bool(vi))
    except (ValueError, gl.Infeasible) as e:
        return type(e).__name__
    return [(f.t_s, f.state, f.gaze_deg) for f in out], s.stats


def batch(t: Any, g: Any, v: Any) -> tuple[list[tuple[float, str, float | None]], dict[str, int]] | str:
    s = gl.GazeStream()
    try:
        frames = s.push_many(t, g, v)
    except (ValueError, gl.Infeasible) as e:
        return type(e).__name__
    return [(f.t_s, f.state, f.gaze_deg) for f in frames], s.stats


dtypes = st.one_of(
    hnp.boolean_dtypes(),
    hnp.integer_dtypes(endianness="?"),
    hnp.unsigned_integer_dtypes(endianness="?"),
    hnp.floating_dtypes(sizes=(16, 32, 64), endianness="?"),
    hnp.complex_number_dtypes(),
    hnp.datetime64_dtypes(),
    hnp.timedelta64_dtypes(),
    hnp.unicode_string_dtypes(max_len=8),
    hnp.byte_string_dtypes(max_len=8),
    st.just(np.dtype(object)),
)


@st.composite
def columns(draw: st.DrawFn) -> tuple[npt.NDArray[Any], npt.NDArray[Any], npt.NDArray[Any] | None]:
    """A track of n samples: times mostly increasing at ~100 Hz (sometimes
    shuffled or repeated), gazes with NaN, valid of any dtype or None, each
    column a C-contiguous, strided or reversed view."""
    n = draw(st.integers(0, 30))
    steps = draw(hnp.arrays(np.float64, n, elements=st.floats(0.0, 0.05)))
    t = np.cumsum(steps)
    if draw(st.booleans()):
        t = t[draw(st.permutations(range(n)))] if n else t
    g = draw(hnp.arrays(np.float64, n, elements=st.one_of(st.floats(-200.0, 400.0), st.just(float("nan")))))
    t_dtype = draw(dtypes)
    v_dtype = draw(st.one_of(st.none(), dtypes))

    def cast(a: npt.NDArray[Any], dtype: np.dtype[Any]) -> npt.NDArray[Any]:
        with np.errstate(all="ignore"):
            if dtype.kind in "Mm":
                return a.astype(np.int64).astype(dtype)
            if dtype.kind == "O":
                return np.array(list(a), dtype=object)
            return a.astype(dtype)

    def view(a: npt.NDArray[Any]) -> npt.NDArray[Any]:
        layout = draw(st.sampled_from(["c", "strided", "reversed"]))
        if layout == "strided":
            wide = np.repeat(a, 2)
            return wide[::2]
        if layout == "reversed":
            return np.ascontiguousarray(a[::-1])[::-1]
        return a

    valid = None
    if v_dtype is not None:
        bits = draw(hnp.arrays(np.bool_, n))
        valid = view(cast(bits, v_dtype))
    return view(cast(t, t_dtype)), view(g), valid


@SETTINGS
@given(columns())
def test_push_many_accepts_exactly_real_times_and_bool_valid(cols: tuple[Any, Any, Any]) -> None:
    t, g, v = cols
    got = batch(t, g, v)
    if t.dtype.kind not in REAL:
        assert got == "ValueError"
        with pytest.raises(ValueError, match="^t_s: expected real numbers, got dtype"):
            gl.GazeStream().push_many(t, g, v)
        return
    if v is not None and v.dtype.kind != "b":
        assert got == "ValueError"
        with pytest.raises(ValueError, match="^valid: expected booleans"):
            gl.GazeStream().push_many(t, g, v)
        return
    assert got == one_by_one(t, g, v)


@pytest.mark.parametrize(
    "valid",
    [
        ["Invalid", "valid"],
        np.array(["True", "False"]),
        [1.0, float("nan")],
        np.array([True, None], dtype=object),
        np.array([True, False], dtype=object),
        [1, 0],
    ],
)
def test_push_many_refuses_non_boolean_valid(valid: Any) -> None:
    with pytest.raises(ValueError, match="^valid: expected booleans"):
        gl.GazeStream().push_many([0.0, 0.01], [90.0, 90.0], valid)


@pytest.mark.parametrize(
    "t_s",
    [
        np.array(["2024-01-01T00:00:00", "2024-01-01T00:00:01"], dtype="datetime64[ns]"),
        np.array([0, 10], dtype="timedelta64[ms]"),
        ["0.0", "0.01"],
        [True, False],
        np.array([0.0, 0.01], dtype=object),
    ],
)
def test_push_many_refuses_non_real_times(t_s: Any) -> None:
    with pytest.raises(ValueError, match="^t_s: expected real numbers"):
        gl.GazeStream().push_many(t_s, [90.0, 90.0])
    with pytest.raises(ValueError, match="^gaze_deg: expected real numbers"):
        gl.GazeStream().push_many([0.0, 0.01], t_s)


def test_push_many_takes_pandas_columns_and_nullable_types() -> None:
    pd = pytest.importorskip("pandas")
    n = 40
    df = pd.DataFrame(
        {
            "t_s": pd.array(np.arange(n) * 0.01, dtype="Float64"),
            "gaze_deg": pd.array(np.full(n, 90.0), dtype="Float64"),
            "valid": pd.array(np.arange(n) % 7 != 0, dtype="boolean"),
        }
    )
    ref = one_by_one(np.arange(n) * 0.01, np.full(n, 90.0), np.arange(n) % 7 != 0)
    assert batch(df["t_s"], df["gaze_deg"], df["valid"]) == ref
    assert batch(df["t_s"].to_numpy(), df["gaze_deg"], df["valid"].astype(bool)) == ref
    # A blank valid cell (pd.NA) or a blank time is refused by name; a
    # blank gaze is an invalid sample, as NaN.
    blank = df["valid"].copy()
    blank[3] = pd.NA
    with pytest.raises(ValueError, match="^valid: expected booleans"):
        gl.GazeStream().push_many(df["t_s"], df["gaze_deg"], blank)
    t = df["t_s"].copy()
    t[3] = pd.NA
    with pytest.raises(ValueError, match=r"^t_s\[3\]: NaN is not a finite number"):
        gl.GazeStream().push_many(t, df["gaze_deg"])
    g = df["gaze_deg"].copy()
    g[3] = pd.NA
    gaze = np.full(n, 90.0)
    gaze[3] = np.nan
    assert batch(df["t_s"], g, df["valid"]) == one_by_one(np.arange(n) * 0.01, gaze, np.arange(n) % 7 != 0)
    # Times as datetimes (a tracker's wall clock) are refused by name.
    with pytest.raises(ValueError, match="^t_s: expected real numbers, got dtype datetime64"):
        gl.GazeStream().push_many(pd.Series(pd.date_range("2024-01-01", periods=n, freq="10ms")), df["gaze_deg"])
