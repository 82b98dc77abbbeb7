//! `gaze_lidar._native`: the Python bindings of the `gaze-lidar` crates.
//!
//! A thin layer: every number comes from the crates' public API (planner,
//! optimizer, checker, eye-safety model, firmware tables, gaze stream,
//! simulator, point-cloud filter); this file only converts arguments and
//! results and maps errors to exceptions with the CLI's one-line messages:
//! `ValueError` for bad input, `Infeasible` for a request that cannot be met,
//! `Rejected` for a profile that fails the checker.

mod replay;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict, PyList};

use gaze_lidar::checker::{
    certify_with, CertifiedProfile, CheckOptions, Verdict as CoreVerdict, Violation,
};
use gaze_lidar::firmware::{FirmwareConfig, FirmwareError, FirmwareTable};
use gaze_lidar::gaze::{GazeSample, State};
use gaze_lidar::model::angle::wrap_deg;
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets::{self, Preset};
use gaze_lidar::names::Named;
use gaze_lidar::pipeline::{
    ClosedFormPlanner, FramePlanner, Notice, PipelineError, PipelineOptions,
};
use gaze_lidar::planner::{closed_form, validate_gaze, Mode, PlanError};
use gaze_lidar::pointcloud::{keep_mask, CloudFrame, CloudOptions};
use gaze_lidar::profile::kinematics::{BinMotion, Timeline};
use gaze_lidar::profile::{Profile as CoreProfile, Region};
use gaze_lidar::sim::{self, KOfN, ModelKind, Scenario, SimConfig, Variant, FOG_LEVELS_PCT};

mod gaze_io;
mod records;
mod runtime;

create_exception!(
    gaze_lidar,
    Infeasible,
    PyException,
    "The request is well-formed but cannot be met (the message names the limit)."
);
create_exception!(
    gaze_lidar,
    Rejected,
    PyException,
    "A profile failed the checker; `violations` lists every violated limit (one line each)."
);

create_exception!(
    gaze_lidar,
    InternalError,
    PyRuntimeError,
    "A bug in gaze-lidar (a Rust panic caught at the binding's edge); please report it with the message."
);

fn panic_error(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_owned());
    InternalError::new_err(format!("internal error: {what}"))
}

/// Runs `f`, turning a Rust panic into [`InternalError`] (a `RuntimeError`)
/// instead of pyo3's `PanicException`, a `BaseException` that `except
/// Exception` misses. Every public entry point runs its body through this.
fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| Err(panic_error(p)))
}

/// As [`guard`], for a computation run with the GIL released.
fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(panic_error)
}

/// A read-only numpy array (the values of an immutable object: a write
/// would be silently lost, so numpy refuses it).
fn frozen_array<'py, T: numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
) -> PyResult<Bound<'py, PyArray1<T>>> {
    let a = PyArray1::from_vec(py, v);
    a.call_method("setflags", (), Some(&[("write", false)].into_py_dict(py)?))?;
    Ok(a)
}

fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

fn rejected(py: Python<'_>, message: String, violations: &[Violation]) -> PyErr {
    let err = Rejected::new_err(message);
    let lines: Vec<String> = violations.iter().map(ToString::to_string).collect();
    // Best effort: the message already says it all.
    let _ = err.value(py).setattr("violations", lines);
    err
}

fn plan_error(py: Python<'_>, e: PlanError) -> PyErr {
    match e {
        PlanError::InvalidInput { field, reason } => {
            value_error(format!("{}: {reason}", field.replace('-', "_")))
        }
        PlanError::Infeasible(_) => Infeasible::new_err(e.to_string()),
        PlanError::Rejected(ref r) => rejected(py, e.to_string(), &r.violations),
    }
}

fn opt_error(py: Python<'_>, e: gaze_lidar::optimizer::OptError) -> PyErr {
    use gaze_lidar::optimizer::OptError;
    match e {
        OptError::Invalid { .. } => value_error(e.to_string()),
        OptError::Rejected(ref r) => rejected(py, e.to_string(), &r.violations),
        OptError::Infeasible(_) | OptError::Solver(_) => Infeasible::new_err(e.to_string()),
    }
}

fn pipeline_error(py: Python<'_>, e: PipelineError) -> PyErr {
    match e {
        PipelineError::Plan(p) => plan_error(py, p),
        PipelineError::Optimizer(o) => opt_error(py, o),
        other if other.is_input_error() => value_error(other.to_string()),
        other => Infeasible::new_err(other.to_string()),
    }
}

fn json_value<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

fn to_py_json<'py, T: serde::Serialize>(py: Python<'py>, v: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(|e| value_error(e.to_string()))?;
    json_value(py, &text)
}

fn preset_of(name: &str) -> PyResult<Preset> {
    presets::preset(name).map_err(|e| value_error(format!("preset: {e}")))
}

fn mode_of(name: &str) -> PyResult<Mode> {
    name.parse().map_err(|e| value_error(format!("mode: {e}")))
}

fn seed_of(seed: i128) -> PyResult<u64> {
    u64::try_from(seed).map_err(|_| value_error(format!("seed: {seed} must lie in 0..=2**64-1")))
}

fn finite(field: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(value_error(format!("{field}: {v} is not a finite number")))
    }
}

/// A certified scan profile (`gaze-lidar/profile@1`): per-bin numpy arrays,
/// the checker's summary, JSON and firmware tables.
#[pyclass(frozen, module = "gaze_lidar", name = "Profile")]
pub struct PyProfile {
    inner: CertifiedProfile,
    /// The preset it was planned on (closed forms), whose sensor and driver
    /// model give its figures; None when unknown (read from JSON alone).
    basis: Option<String>,
}

impl PyProfile {
    fn column<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&gaze_lidar::profile::Bin) -> f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        frozen_array(py, self.inner.profile().bins.iter().map(f).collect())
    }

    /// `f(bin, azimuth)` at each azimuth (degrees, any real: wrapped by the
    /// crate's `wrap_deg`), in the input's shape; the bin is the core
    /// timeline's (`Timeline::bin_index`, the last bin starting at or before).
    fn at_azimuths<'py>(
        &self,
        py: Python<'py>,
        azimuth_deg: &Bound<'py, PyAny>,
        f: impl Fn(&gaze_lidar::profile::Bin, f64) -> f64 + Sync,
    ) -> PyResult<Bound<'py, PyAny>> {
        let np = py.import("numpy")?;
        let a = np.call_method1("asarray", (azimuth_deg, "float64"))?;
        let shape = a.getattr("shape")?;
        let flat = np.call_method1("ascontiguousarray", (a.call_method0("ravel")?,))?;
        let flat: PyReadonlyArray1<'py, f64> = flat.extract()?;
        let xs = flat.as_slice()?;
        let p = self.inner.profile();
        let out = detached(py, || {
            let timeline = Timeline::new(p);
            xs.iter()
                .map(|&az| {
                    if !az.is_finite() {
                        return Err(az);
                    }
                    let a = wrap_deg(az);
                    let b = &p.bins[timeline.bin_index(a)];
                    Ok(f(b, a))
                })
                .collect::<Result<Vec<f64>, f64>>()
        })?
        .map_err(|az| value_error(format!("azimuth_deg: {az} is not a finite angle")))?;
        frozen_array(py, out)?.call_method1("reshape", (shape,))
    }

    fn json(&self) -> PyResult<String> {
        self.inner
            .profile()
            .to_json()
            .map_err(|e| value_error(e.to_string()))
    }

    fn parse(py: Python<'_>, text: &str, basis: Option<&str>) -> PyResult<Self> {
        if let Some(name) = basis {
            preset_of(name)?;
        }
        let p = CoreProfile::from_json(text, "<json>").map_err(|e| value_error(e.to_string()))?;
        certify_with(p, &CheckOptions::declared())
            .map(|inner| Self {
                inner,
                basis: basis.map(str::to_owned),
            })
            .map_err(|r| rejected(py, r.to_string(), &r.violations))
    }

    fn firmware_table(
        &self,
        tick_hz: i128,
        power_w_per_code: Option<f64>,
    ) -> PyResult<FirmwareTable> {
        let tick_hz = u64::try_from(tick_hz)
            .map_err(|_| value_error(format!("tick_hz: {tick_hz} must lie in 1..=1e10")))?;
        let cfg = FirmwareConfig {
            tick_hz,
            power_w_per_code,
        };
        FirmwareTable::from_certified(&self.inner, &cfg).map_err(|e| match e {
            FirmwareError::Config { .. } => value_error(format!("firmware: {e}")),
            other => Infeasible::new_err(format!("firmware: {other}")),
        })
    }
}

#[pymethods]
impl PyProfile {
    /// Bin start azimuths, degrees (ISO 8855, counter-clockwise from ahead).
    #[getter]
    fn start_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, |b| b.start_deg)
    }
    /// Bin widths, degrees.
    #[getter]
    fn width_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, |b| b.width_deg)
    }
    /// Laser power per bin, W.
    #[getter]
    fn power_w<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, |b| b.power_w)
    }
    /// Spin at each bin's start, rad/s.
    #[getter]
    fn spin_start_rad_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, |b| b.spin_start_rad_s)
    }
    /// Spin at each bin's end, rad/s.
    #[getter]
    fn spin_end_rad_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, |b| b.spin_end_rad_s)
    }
    /// Dwell time per bin, s.
    #[getter]
    fn dwell_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.column(py, gaze_lidar::profile::Bin::dwell_time_s)
    }
    /// Whether each bin lies in the driver's region of focus.
    #[getter]
    fn in_rof<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        frozen_array(
            py,
            self.inner
                .profile()
                .bins
                .iter()
                .map(|b| b.region == Some(Region::Rof))
                .collect(),
        )
    }
    /// Gaze azimuth the profile was built for, degrees; None for the baseline.
    #[getter]
    fn gaze_deg(&self) -> Option<f64> {
        self.inner.profile().gaze_deg
    }
    /// How it was made (e.g. "closed-form range").
    #[getter]
    fn mode(&self) -> Option<String> {
        self.inner.profile().mode.clone()
    }
    /// Nominal revolutions per second, Hz.
    #[getter]
    fn frame_rate_hz(&self) -> f64 {
        self.inner.profile().frame_rate_hz
    }
    /// Laser firing rate per channel, Hz.
    #[getter]
    fn pulse_rate_hz(&self) -> f64 {
        self.inner.profile().pulse_rate_hz
    }
    /// The average power budget, W.
    #[getter]
    fn average_power_w(&self) -> f64 {
        self.inner.profile().average_power_w
    }
    /// "time" or "angle".
    #[getter]
    fn power_accounting(&self) -> String {
        self.inner.profile().power_accounting.to_string()
    }
    /// The declared limits (profile@1 `limits`), as a dict.
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| to_py_json(py, &self.inner.profile().limits))
    }
    /// The checker's figures (average powers, frame period, ranges …), as a dict.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| to_py_json(py, self.inner.summary()))
    }
    /// The optimizer's figures (profile@1 `optimality`: objective,
    /// upper_bound, gap, exact, global, figures), as a dict; None for a
    /// profile without them (the closed forms).
    #[getter]
    fn optimality<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        guard(|| {
            self.inner
                .profile()
                .optimality
                .as_ref()
                .map(|o| to_py_json(py, o))
                .transpose()
        })
    }
    /// The range (m) and points per degree inside the region of focus
    /// ("rof") and outside it ("roi"), each {"mean", "min", "max"} over the
    /// region's bins (angle-weighted mean), and the closed form's for the
    /// same gaze ("closed_form", or "closed_form_rejected" saying why
    /// there is none): profile@1 `optimality.figures`, as a dict. A profile
    /// without them that knows its preset (a closed form, a stream frame)
    /// gets its own ("profile" only: it is the closed form), from the same
    /// `planner::figures::region_figures`; None otherwise.
    #[getter]
    fn figures<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        guard(|| {
            let p = self.inner.profile();
            if let Some(f) = p.optimality.as_ref().and_then(|o| o.figures.as_ref()) {
                return to_py_json(py, f).map(Some);
            }
            let Some(name) = &self.basis else {
                return Ok(None);
            };
            let preset = preset_of(name)?;
            let own = gaze_lidar::planner::figures::region_figures(p, &preset.lidar, &preset.focus);
            let f = gaze_lidar::profile::UnitFigures {
                profile: own,
                closed_form: None,
                closed_form_rejected: None,
            };
            to_py_json(py, &f).map(Some)
        })
    }
    /// The bins as columns (start_deg, width_deg, power_w,
    /// spin_start_rad_s, spin_end_rad_s, dwell_s, in_rof: numpy arrays)
    /// plus range_m and points_per_deg per bin when the profile knows its
    /// preset.
    fn to_dict<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| records::profile_columns(slf.py(), slf.get()))
    }
    /// `to_dict()` as a DataFrame, one row per bin. Needs pandas.
    fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            records::pandas(slf.py(), "Profile.to_pandas")?.call_method1(
                "DataFrame",
                (records::profile_columns(slf.py(), slf.get())?,),
            )
        })
    }
    /// The profile as `gaze-lidar/profile@1` JSON.
    fn to_json(&self) -> PyResult<String> {
        guard(|| {
            self.inner
                .profile()
                .to_json()
                .map_err(|e| value_error(e.to_string()))
        })
    }
    /// Parses profile@1 JSON and certifies it against its declared limits.
    ///
    /// Raises ValueError for malformed JSON (line:column and field named)
    /// and Rejected when a limit is violated.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        guard(|| Self::parse(py, text, None))
    }
    /// `Profile(text, preset=None)`: `from_json`, and with `preset` the
    /// preset whose sensor and driver model give its `figures`.
    #[new]
    #[pyo3(signature = (text, preset=None))]
    fn new(py: Python<'_>, text: &str, preset: Option<&str>) -> PyResult<Self> {
        guard(|| Self::parse(py, text, preset))
    }
    /// The preset the profile was planned on (closed forms and stream
    /// frames), None when unknown (a profile read from JSON alone).
    #[getter]
    fn preset(&self) -> Option<String> {
        self.basis.clone()
    }
    /// Laser power at each azimuth (degrees, any shape; wrapped into
    /// [0, 360)), W: the power of the bin holding it, as the checker and the
    /// simulator see it. Returns a read-only float64 array of the same shape.
    fn power_w_at<'py>(
        &self,
        py: Python<'py>,
        azimuth_deg: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| self.at_azimuths(py, azimuth_deg, |b, _| b.power_w))
    }
    /// Head spin at each azimuth (degrees, any shape; wrapped into [0, 360)),
    /// rad/s: profile@1's constant angular acceleration within a bin,
    /// `ω(x) = √(ω_start² + 2ax)` (the core kinematics' `spin_into_rad_s`).
    /// Returns a read-only float64 array of the same shape.
    fn spin_rad_s_at<'py>(
        &self,
        py: Python<'py>,
        azimuth_deg: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            self.at_azimuths(py, azimuth_deg, |b, a| {
                b.spin_into_rad_s((a - b.start_deg).to_radians())
            })
        })
    }
    fn __eq__(&self, other: PyRef<'_, Self>) -> PyResult<bool> {
        guard(|| Ok(self.json()? == other.json()?))
    }
    fn __hash__(&self) -> PyResult<u64> {
        use std::hash::{Hash, Hasher};
        guard(|| {
            let mut h = std::collections::hash_map::DefaultHasher::new();
            self.json()?.hash(&mut h);
            Ok(h.finish())
        })
    }
    /// Pickles through its profile@1 JSON (re-certified when loaded) and
    /// its preset.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, pyo3::types::PyType>, (String, Option<String>))> {
        guard(|| Ok((slf.get_type(), (slf.get().json()?, slf.get().basis.clone()))))
    }
    fn __copy__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }
    /// A new Profile from this one's JSON (it is immutable, so equal to it).
    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyAny>) -> PyResult<Self> {
        guard(|| Self::parse(py, &self.json()?, self.basis.as_deref()))
    }
    /// Integer firmware tables: a dict of scalars and numpy integer arrays.
    #[pyo3(signature = (tick_hz=80_000_000, power_w_per_code=None))]
    fn firmware<'py>(
        &self,
        py: Python<'py>,
        tick_hz: i128,
        power_w_per_code: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let t = self.firmware_table(tick_hz, power_w_per_code)?;
            let d = PyDict::new(py);
            d.set_item("format", &t.format)?;
            d.set_item("tick_hz", t.tick_hz)?;
            d.set_item("frame_ticks", t.frame_ticks)?;
            d.set_item("power_w_per_code", t.power_w_per_code)?;
            d.set_item("power_accounting", t.power_accounting.to_string())?;
            d.set_item("pulse_rate_hz", t.pulse_rate_hz)?;
            d.set_item("limits", to_py_json(py, &t.limits)?)?;
            d.set_item("eye_safety", to_py_json(py, &t.eye_safety)?)?;
            let b = &t.bins;
            d.set_item(
                "start_deg",
                PyArray1::from_vec(py, b.iter().map(|b| b.start_deg).collect()),
            )?;
            d.set_item(
                "width_mdeg",
                PyArray1::from_vec(py, b.iter().map(|b| b.width_mdeg).collect()),
            )?;
            d.set_item(
                "dwell_ticks",
                PyArray1::from_vec(py, b.iter().map(|b| b.dwell_ticks).collect()),
            )?;
            d.set_item(
                "power_code",
                PyArray1::from_vec(py, b.iter().map(|b| b.power_code).collect()),
            )?;
            d.set_item(
                "dwell_ticks_min",
                PyArray1::from_vec(py, b.iter().map(|b| b.dwell_ticks_min).collect()),
            )?;
            d.set_item(
                "dwell_ticks_max",
                PyArray1::from_vec(py, b.iter().map(|b| b.dwell_ticks_max).collect()),
            )?;
            d.set_item(
                "power_code_cap",
                PyArray1::from_vec(py, b.iter().map(|b| b.power_code_cap).collect()),
            )?;
            Ok(d)
        })
    }
    /// The firmware table as `gaze-lidar/firmware@1` JSON.
    #[pyo3(signature = (tick_hz=80_000_000, power_w_per_code=None))]
    fn firmware_json(&self, tick_hz: i128, power_w_per_code: Option<f64>) -> PyResult<String> {
        guard(|| {
            self.firmware_table(tick_hz, power_w_per_code)?
                .to_json()
                .map_err(|e| value_error(e.to_string()))
        })
    }
    fn __len__(&self) -> usize {
        self.inner.profile().bins.len()
    }
    fn __repr__(&self) -> String {
        let p = self.inner.profile();
        let s = self.inner.summary();
        format!(
            "<gaze_lidar.Profile {} bins, mode={:?}, gaze_deg={}, {} Hz, power {:.4}–{:.4} W, spin {:.4}–{:.4} rad/s>",
            p.bins.len(),
            p.mode.as_deref().unwrap_or("?"),
            p.gaze_deg.map_or("None".to_owned(), |g| g.to_string()),
            p.frame_rate_hz,
            s.power_w_range[0],
            s.power_w_range[1],
            s.spin_rad_s_range[0],
            s.spin_rad_s_range[1],
        )
    }
}

/// The paper's closed-form controller (eq. 3–6), certified.
///
/// mode "baseline" ignores gaze_deg (the uniform, fail-safe profile); the
/// others need it (degrees, ISO 8855: 90 looks left; the LiDAR then
/// favours the side the driver is *not* watching). bins: 4..=36000 equal
/// bins (region boundaries are added as edges). accounting ("time" or
/// "angle") overrides the preset's power accounting. Raises ValueError
/// (e.g. "gaze_deg: NaN is not a finite azimuth …"), Infeasible, or
/// Rejected (e.g. a spin step on a motor with an acceleration limit).
#[pyfunction]
#[pyo3(
    signature = (preset="paper", mode="range", gaze_deg=Some(90.0), bins=360, accounting=None),
    text_signature = "(preset='paper', mode='range', gaze_deg=90.0, bins=360, accounting=None)"
)]
fn profile(
    py: Python<'_>,
    preset: &str,
    mode: &str,
    gaze_deg: Option<f64>,
    bins: i64,
    accounting: Option<&str>,
) -> PyResult<PyProfile> {
    guard(|| {
        let preset_name = preset;
        let mut preset = preset_of(preset)?;
        let mode = mode_of(mode)?;
        if let Some(acc) = accounting {
            preset.lidar.power_accounting = match acc {
                "time" => PowerAccounting::Time,
                "angle" => PowerAccounting::Angle,
                other => {
                    return Err(value_error(format!(
                        "accounting: '{other}' is not one of time, angle"
                    )))
                }
            };
        }
        if let Some(g) = gaze_deg {
            validate_gaze(g).map_err(|e| plan_error(py, e))?;
        }
        let gaze = match (mode, gaze_deg) {
            (Mode::Baseline, _) => None,
            (_, Some(g)) => Some(g),
            (m, None) => {
                return Err(value_error(format!(
                    "gaze_deg: required for mode {}",
                    m.name()
                )))
            }
        };
        let bins = usize::try_from(bins)
            .map_err(|_| value_error(format!("bins: {bins} must lie in [4, 36000]")))?;
        closed_form(&preset, mode, gaze, bins)
            .map(|inner| PyProfile {
                inner,
                basis: Some(preset_name.to_owned()),
            })
            .map_err(|e| plan_error(py, e))
    })
}

/// The optimizer's certified profile (HiGHS) for a configuration
/// as `gaze-lidar profile --config` reads it (see examples/configs/):
/// TOML text, or with json=True the same keys as JSON text.
/// Releases the GIL while solving. Raises ValueError for a bad key (named),
/// Infeasible naming the limit. `gaze_lidar.optimize` also takes a dict or
/// a path.
#[pyfunction]
#[pyo3(signature = (config_text, gaze_deg, json=false))]
fn optimize(py: Python<'_>, config_text: &str, gaze_deg: f64, json: bool) -> PyResult<PyProfile> {
    use gaze_lidar::optimizer::{OptError, OptimizerConfig};
    guard(|| {
        validate_gaze(gaze_deg).map_err(|e| plan_error(py, e))?;
        let config = if json {
            serde_json::from_str::<OptimizerConfig>(config_text).map_err(|e| OptError::Invalid {
                field: "config".to_owned(),
                reason: e.to_string(),
            })
        } else {
            OptimizerConfig::from_toml(config_text, "config")
        };
        let (problem, named) = config
            .and_then(|c| Ok((c.problem()?, c.preset()?)))
            .map_err(|e| opt_error(py, e))?;
        // Ctrl-C returns at once (the solve finishes in the background); a
        // pool of its own should the solver's path ever use rayon.
        runtime::interruptible(py, true, move |_| {
            gaze_lidar::optimizer::optimize(&problem, gaze_deg).map(|c| {
                gaze_lidar::optimizer::figures::attach_to_optimum(c, &problem, named.levels)
            })
        })?
        .map(|inner| PyProfile { inner, basis: None })
        .map_err(|e| opt_error(py, e))
    })
}

/// The checker's verdict on a profile@1 file.
#[pyclass(frozen, module = "gaze_lidar", name = "Verdict")]
#[derive(Clone, PartialEq)]
pub struct Verdict {
    /// Whether every limit holds.
    #[pyo3(get)]
    certified: bool,
    /// One line per violated limit (empty when certified).
    #[pyo3(get)]
    violations: Vec<String>,
    /// The limit each violation is about (profile@1 key), in the same order.
    #[pyo3(get)]
    limits: Vec<String>,
    /// Worst eye-safety exposure / Class 1 limit (> 1 fails); None when not evaluated.
    #[pyo3(get)]
    worst_ratio: Option<f64>,
    /// The eye-safety rule that binds at the worst azimuth.
    #[pyo3(get)]
    binding_rule: Option<String>,
    /// Azimuth of the worst eye-safety exposure, degrees.
    #[pyo3(get)]
    worst_azimuth_deg: Option<f64>,
    /// Channels of the head eye safety was evaluated for; None for one
    /// channel (no head given) or when not evaluated.
    #[pyo3(get)]
    head_channels: Option<u32>,
    /// The largest uniform power scale (every bin power times it) at which
    /// the profile's eye safety certifies; None when not evaluated.
    #[pyo3(get)]
    power_scale_to_certify: Option<f64>,
}

type VerdictArgs = (
    bool,
    Vec<String>,
    Vec<String>,
    Option<f64>,
    Option<String>,
    Option<f64>,
    Option<u32>,
    Option<f64>,
);

impl Verdict {
    /// Python's view of the core's verdict.
    fn of(v: &CoreVerdict) -> Self {
        let eye = v.eye_safety.as_ref();
        Self {
            certified: v.certified,
            violations: v.violations.iter().map(|e| e.message.clone()).collect(),
            limits: v.violations.iter().map(|e| e.limit.to_owned()).collect(),
            worst_ratio: eye.map(|r| r.worst_ratio),
            binding_rule: eye.map(|r| r.binding_rule.to_string()),
            worst_azimuth_deg: eye.map(|r| r.worst_azimuth_deg),
            head_channels: eye
                .and_then(|r| r.head.as_ref())
                .map(|h| h.channels_evaluated),
            power_scale_to_certify: eye.map(|r| r.power_scale_to_certify),
        }
    }
}

#[pymethods]
impl Verdict {
    /// A verdict from its fields (what pickle calls; `check` makes them).
    #[new]
    #[pyo3(signature = (certified, violations, limits, worst_ratio=None, binding_rule=None, worst_azimuth_deg=None, head_channels=None, power_scale_to_certify=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        certified: bool,
        violations: Vec<String>,
        limits: Vec<String>,
        worst_ratio: Option<f64>,
        binding_rule: Option<String>,
        worst_azimuth_deg: Option<f64>,
        head_channels: Option<u32>,
        power_scale_to_certify: Option<f64>,
    ) -> PyResult<Self> {
        if violations.len() != limits.len() {
            return Err(value_error(format!(
                "limits: one per violation, got {} limits for {} violations",
                limits.len(),
                violations.len()
            )));
        }
        if certified && !violations.is_empty() {
            return Err(value_error(
                "violations: a certified verdict has none".to_owned(),
            ));
        }
        Ok(Self {
            certified,
            violations,
            limits,
            worst_ratio,
            binding_rule,
            worst_azimuth_deg,
            head_channels,
            power_scale_to_certify,
        })
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, pyo3::types::PyType>, VerdictArgs) {
        let v = slf.get().clone();
        (
            slf.get_type(),
            (
                v.certified,
                v.violations,
                v.limits,
                v.worst_ratio,
                v.binding_rule,
                v.worst_azimuth_deg,
                v.head_channels,
                v.power_scale_to_certify,
            ),
        )
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Self>().is_ok_and(|o| *o.get() == *self)
    }
    /// The fields as a dict (what `to_pandas` tabulates).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("certified", self.certified)?;
        d.set_item("violations", self.violations.clone())?;
        d.set_item("limits", self.limits.clone())?;
        d.set_item("worst_ratio", self.worst_ratio)?;
        d.set_item("binding_rule", self.binding_rule.clone())?;
        d.set_item("worst_azimuth_deg", self.worst_azimuth_deg)?;
        d.set_item("head_channels", self.head_channels)?;
        d.set_item("power_scale_to_certify", self.power_scale_to_certify)?;
        Ok(d)
    }
    /// One row per violation (limit, violation) with the verdict's scalars
    /// on every row (a certified verdict: one row, limit and violation
    /// None). Needs pandas.
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = records::pandas(py, "Verdict.to_pandas")?;
        let rows = PyList::empty(py);
        let pairs: Vec<(Option<&str>, Option<&str>)> = if self.violations.is_empty() {
            vec![(None, None)]
        } else {
            self.limits
                .iter()
                .zip(&self.violations)
                .map(|(l, v)| (Some(l.as_str()), Some(v.as_str())))
                .collect()
        };
        for (limit, violation) in pairs {
            let d = self.to_dict(py)?;
            d.del_item("violations")?;
            d.del_item("limits")?;
            d.set_item("limit", limit)?;
            d.set_item("violation", violation)?;
            rows.append(d)?;
        }
        pd.call_method1("DataFrame", (rows,))
    }
    fn __bool__(&self) -> bool {
        self.certified
    }
    fn __repr__(&self) -> String {
        format!(
            "<gaze_lidar.Verdict certified={} violations={}>",
            if self.certified { "True" } else { "False" },
            self.violations.len()
        )
    }
}

/// Verifies profile@1 JSON against its declared limits (and a preset's sensor).
#[pyfunction]
#[pyo3(signature = (profile_json, preset=None, *, no_eye_safety=false))]
fn check(
    py: Python<'_>,
    profile_json: &str,
    preset: Option<&str>,
    no_eye_safety: bool,
) -> PyResult<Verdict> {
    guard(|| {
        let profile = CoreProfile::from_json(profile_json, "profile_json")
            .map_err(|e| value_error(e.to_string()))?;
        let sensor = preset.map(preset_of).transpose()?;
        // A many-bin, many-channel check: Ctrl-C returns at once (the
        // checker finishes in the background, its verdict dropped).
        runtime::interruptible(py, false, move |_| {
            let opts = match &sensor {
                Some(s) => CheckOptions::for_sensor(&s.lidar),
                None => CheckOptions::declared(),
            }
            .allow_missing_eye_safety(no_eye_safety);
            let result = certify_with(profile.clone(), &opts);
            // The core's one verdict, built from the checker's own
            // evaluation (what `gaze-lidar check --format json` prints).
            Verdict::of(&CoreVerdict::of(
                &result,
                &profile,
                sensor.as_ref().map(|s| &s.lidar),
            ))
        })
    })
}

/// One LiDAR frame of a gaze stream.
#[pyclass(frozen, module = "gaze_lidar", name = "Frame")]
pub struct PyFrame {
    /// Frame start on the gaze clock, s.
    #[pyo3(get)]
    t_s: f64,
    /// "adaptive" or "fail_safe".
    #[pyo3(get)]
    state: &'static str,
    profile: Py<PyProfile>,
}

#[pymethods]
impl PyFrame {
    /// A frame from its fields (what pickle calls; streams make them).
    #[new]
    fn new(t_s: f64, state: &str, profile: Py<PyProfile>) -> PyResult<Self> {
        let state = match state {
            "adaptive" => "adaptive",
            "fail_safe" => "fail_safe",
            other => {
                return Err(value_error(format!(
                    "state: '{other}' is not one of adaptive, fail_safe"
                )))
            }
        };
        Ok(Self {
            t_s: finite("t_s", t_s)?,
            state,
            profile,
        })
    }
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, pyo3::types::PyType>,
        (f64, &'static str, Py<PyProfile>),
    ) {
        let f = slf.get();
        (
            slf.get_type(),
            (f.t_s, f.state, f.profile.clone_ref(slf.py())),
        )
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        guard(|| {
            let Ok(o) = other.cast::<Self>() else {
                return Ok(false);
            };
            let o = o.get();
            Ok(self.t_s.to_bits() == o.t_s.to_bits()
                && self.state == o.state
                && self.profile.get().json()? == o.profile.get().json()?)
        })
    }
    /// t_s, state, gaze_deg and the profile's mode as a dict (one row of
    /// `gaze_lidar.frames_to_pandas`).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("t_s", self.t_s)?;
        d.set_item("state", self.state)?;
        d.set_item("gaze_deg", self.gaze_deg())?;
        d.set_item("mode", self.profile.get().inner.profile().mode.clone())?;
        Ok(d)
    }
    /// The frame's profile, one row per bin (`Profile.to_pandas`), with
    /// t_s, state and gaze_deg on every row. Needs pandas.
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let df = records::pandas(py, "Frame.to_pandas")?.call_method1(
            "DataFrame",
            (records::profile_columns(py, self.profile.get())?,),
        )?;
        df.call_method1("insert", (0, "t_s", self.t_s))?;
        df.call_method1("insert", (1, "state", self.state))?;
        df.call_method1("insert", (2, "gaze_deg", self.gaze_deg()))?;
        Ok(df)
    }
    /// The certified profile the LiDAR runs during this frame.
    #[getter]
    fn profile(&self, py: Python<'_>) -> Py<PyProfile> {
        self.profile.clone_ref(py)
    }
    /// The gaze the profile was built for, degrees; None in fail-safe.
    #[getter]
    fn gaze_deg(&self) -> Option<f64> {
        self.profile.get().inner.profile().gaze_deg
    }
    fn __repr__(&self) -> String {
        // The frame clock counts whole microseconds: show t_s at that
        // resolution (0.05, not 0.049999999999999996).
        format!(
            "<gaze_lidar.Frame t_s={} state={} gaze_deg={}>",
            (self.t_s * 1e6).round() / 1e6,
            self.state,
            self.profile
                .get()
                .inner
                .profile()
                .gaze_deg
                .map_or("None".to_owned(), |g| g.to_string())
        )
    }
}

type Stream = gaze_lidar::pipeline::GazeStream<Box<dyn FramePlanner + Send>>;

/// The frame planner of a `GazeStream` or a replay, and the rated range of
/// its sensor, m: the optimizer's fast path on `config_toml` (`mode`
/// replacing its objective's), else the preset's closed form on `bins`
/// equal bins (`4..=max_bins`; `bins_note` follows the range in the
/// message), planned once at gaze 0 so that an impossible request fails
/// here rather than at the first frame.
#[allow(clippy::too_many_arguments)]
fn frame_planner(
    py: Python<'_>,
    preset: &str,
    mode: Mode,
    bins: i64,
    max_bins: usize,
    bins_note: &str,
    config_toml: Option<&str>,
) -> PyResult<(Box<dyn FramePlanner + Send>, f64)> {
    if let Some(text) = config_toml {
        use gaze_lidar::optimizer::OptimizerConfig;
        let mut problem = OptimizerConfig::from_toml(text, "config_toml")
            .and_then(|c| c.problem())
            .map_err(|e| opt_error(py, e))?;
        problem.objective.mode = mode;
        let rated = problem.lidar.rated_range_m;
        let p = gaze_lidar::pipeline::OptimizerPlanner::new(problem)
            .map_err(|e| pipeline_error(py, e))?;
        return Ok((Box::new(p), rated));
    }
    let bins = usize::try_from(bins)
        .ok()
        .filter(|b| (gaze_lidar::model::angle::MIN_BINS..=max_bins).contains(b))
        .ok_or_else(|| {
            value_error(format!(
                "bins: {bins} must lie in [4, {max_bins}]{bins_note}"
            ))
        })?;
    let preset = preset_of(preset)?;
    closed_form(&preset, mode, Some(0.0), bins).map_err(|e| plan_error(py, e))?;
    let rated = preset.lidar.rated_range_m;
    Ok((Box::new(ClosedFormPlanner { preset, mode, bins }), rated))
}

/// Gaze samples in, one certified profile per LiDAR frame out.
///
/// The frame clock drives the fail-safe (the CLI's `stream` rules): frame k
/// starts at t0 + k·T (t0 the first sample or tick, T the frame period); a
/// frame is adaptive only if the newest fixation is no older than
/// timeout_ms when it is decided, and after a loss only once
/// recover_samples consecutive valid samples arrived (so the first
/// adaptive frame comes after 4 valid samples by default); otherwise it
/// runs the uniform baseline. A timestamp jump of more than max_gap_frames
/// periods emits one fail-safe frame and restarts the clock. The settings
/// take the ranges of the CLI's options: timeout_ms in (0, 1e7), rounded to
/// a microsecond; recover_samples 1..=100000; saccade_deg_s in (0, 1e6);
/// max_gap_frames 0..=1000000.
///
/// With config_toml, frames are planned by the optimizer's fast path (mode
/// overrides the objective); otherwise by the preset's closed form.
///
/// Thread-safe: an internal lock serialises calls, so a CARLA
/// `sensor.listen` callback (CARLA's own thread) and the main thread may
/// share one stream; planning runs with the GIL released.
#[pyclass(frozen, module = "gaze_lidar", name = "GazeStream")]
pub struct PyGazeStream {
    inner: Mutex<Stream>,
    preset: String,
    mode: &'static str,
    /// The frames' preset (closed-form planning), None with config_toml.
    basis: Option<String>,
}

impl PyGazeStream {
    #[allow(clippy::too_many_arguments)]
    fn build(
        py: Python<'_>,
        preset: &str,
        mode: &str,
        timeout_ms: f64,
        bins: i64,
        recover_samples: i64,
        saccade_deg_s: f64,
        max_gap_frames: i64,
        config_toml: Option<&str>,
    ) -> PyResult<Self> {
        let preset_name = preset.to_owned();
        let pipeline = PipelineOptions {
            timeout_ms,
            saccade_deg_s,
            recover_samples,
            max_gap_frames,
        }
        .config()
        .map_err(|e| pipeline_error(py, e))?;
        let mode = mode_of(mode)?;
        let (planner, _) = frame_planner(
            py,
            preset,
            mode,
            bins,
            gaze_lidar::model::angle::MAX_BINS,
            "",
            config_toml,
        )?;
        Ok(Self {
            inner: Mutex::new(gaze_lidar::pipeline::GazeStream::with_config(
                planner,
                pipeline.filter,
                pipeline.failsafe,
                pipeline.stream,
            )),
            basis: config_toml.is_none().then(|| preset_name.clone()),
            preset: preset_name,
            mode: mode.name(),
        })
    }

    /// Runs `f` on the stream under its lock, with the GIL released (so a
    /// thread waiting for the lock never holds the GIL its holder needs).
    fn locked<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Stream) -> T + Send,
    ) -> PyResult<T> {
        detached(py, || {
            self.inner.lock().map(|mut s| f(&mut s)).map_err(|_| ())
        })?
        .map_err(|()| {
            InternalError::new_err(
                "internal error: the stream's lock was poisoned by an earlier internal error; create a new GazeStream",
            )
        })
    }
}

fn frames(
    py: Python<'_>,
    frames: Vec<gaze_lidar::pipeline::Frame>,
    basis: Option<&str>,
) -> PyResult<Vec<PyFrame>> {
    frames
        .into_iter()
        .map(|f| {
            Ok(PyFrame {
                t_s: f.t_s,
                state: match f.state {
                    State::Adaptive => "adaptive",
                    State::FailSafe => "fail_safe",
                },
                profile: Py::new(
                    py,
                    PyProfile {
                        inner: f.profile,
                        basis: basis.map(str::to_owned),
                    },
                )?,
            })
        })
        .collect()
}

#[pymethods]
impl PyGazeStream {
    #[new]
    #[pyo3(signature = (preset="paper", mode="range", timeout_ms=100.0, *, bins=360, recover_samples=4, saccade_deg_s=30.0, max_gap_frames=200, config_toml=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        preset: &str,
        mode: &str,
        timeout_ms: f64,
        bins: i64,
        recover_samples: i64,
        saccade_deg_s: f64,
        max_gap_frames: i64,
        config_toml: Option<&str>,
    ) -> PyResult<Self> {
        guard(|| {
            Self::build(
                py,
                preset,
                mode,
                timeout_ms,
                bins,
                recover_samples,
                saccade_deg_s,
                max_gap_frames,
                config_toml,
            )
        })
    }

    /// Feeds one tracker sample (gaze clock t_s, s; gaze_deg in degrees,
    /// ISO 8855: 90 looks left); returns the frames that start at or before
    /// it, each decided from the samples before it. valid=False (or a
    /// non-finite gaze) means the tracker lost the eyes.
    #[pyo3(signature = (t_s, gaze_deg, valid=true))]
    fn push(&self, py: Python<'_>, t_s: f64, gaze_deg: f64, valid: bool) -> PyResult<Vec<PyFrame>> {
        guard(|| {
            finite("t_s", t_s)?;
            let sample = GazeSample {
                t_s,
                gaze_deg,
                valid,
            };
            let out = self
                .locked(py, |s| s.push(&sample))?
                .map_err(|e| pipeline_error(py, e))?;
            frames(py, out, self.basis.as_deref())
        })
    }

    /// Feeds a recorded gaze track (1-D arrays of equal length, array-likes
    /// accepted: times t_s in s, gaze_deg in degrees, valid as bools or None
    /// for all valid) in order, as many push calls would; returns all the
    /// frames they emit. The GIL is released for the whole batch.
    #[pyo3(signature = (t_s, gaze_deg, valid=None))]
    fn push_many<'py>(
        &self,
        py: Python<'py>,
        t_s: &Bound<'py, PyAny>,
        gaze_deg: &Bound<'py, PyAny>,
        valid: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Vec<PyFrame>> {
        guard(|| {
            let np = py.import("numpy")?;
            // numpy's dtype kinds each argument may have: numbers for the
            // times and azimuths (never bools, dates, strings or objects),
            // bools only for `valid` (never "Invalid", NaN or None).
            let column =
                |name: &str, a: &Bound<'py, PyAny>, dtype: &str| -> PyResult<Bound<'py, PyAny>> {
                    let (kinds, what) = if dtype == "bool" {
                        ("b", "booleans (a bool array, or None for all valid)")
                    } else {
                        ("fiu", "real numbers")
                    };
                    let raw = np
                        .call_method1("asarray", (a,))
                        .map_err(|e| value_error(format!("{name}: not an array: {e}")))?;
                    let dt = raw.getattr("dtype")?;
                    let kind: String = dt.getattr("kind")?.extract()?;
                    if !kinds.contains(kind.as_str()) {
                        return Err(value_error(format!(
                            "{name}: expected {what}, got dtype {dt}"
                        )));
                    }
                    let c = np.call_method1("ascontiguousarray", (raw, dtype))?;
                    let ndim: usize = c.getattr("ndim")?.extract()?;
                    if ndim != 1 {
                        return Err(value_error(format!(
                            "{name}: expected a 1-D array, got {ndim} dimensions"
                        )));
                    }
                    Ok(c)
                };
            let t = column("t_s", t_s, "float64")?;
            let g = column("gaze_deg", gaze_deg, "float64")?;
            let t: PyReadonlyArray1<'py, f64> = t.extract()?;
            let g: PyReadonlyArray1<'py, f64> = g.extract()?;
            let v: Option<PyReadonlyArray1<'py, bool>> = match valid {
                None => None,
                Some(v) => Some(column("valid", v, "bool")?.extract()?),
            };
            let (t, g) = (t.as_slice()?, g.as_slice()?);
            let v = v.as_ref().map(|v| v.as_slice()).transpose()?;
            let n = t.len();
            if g.len() != n || v.is_some_and(|v| v.len() != n) {
                return Err(value_error(format!(
                    "gaze_deg: t_s, gaze_deg and valid must have one length, got {n}, {}{}",
                    g.len(),
                    v.map_or(String::new(), |v| format!(", {}", v.len()))
                )));
            }
            if let Some(i) = t.iter().position(|x| !x.is_finite()) {
                return Err(value_error(format!(
                    "t_s[{i}]: {} is not a finite number",
                    t[i]
                )));
            }
            let out = self
                .locked(py, |s| {
                    let mut out = Vec::new();
                    for i in 0..n {
                        let sample = GazeSample {
                            t_s: t[i],
                            gaze_deg: g[i],
                            valid: v.is_none_or(|v| v[i]),
                        };
                        out.extend(s.push(&sample)?);
                    }
                    Ok(out)
                })?
                .map_err(|e| pipeline_error(py, e))?;
            frames(py, out, self.basis.as_deref())
        })
    }

    /// Runs the frame clock to now_s without a sample: the frames due by
    /// then, fail-safe once the last fixation is older than the timeout.
    /// Call it on each LiDAR frame so silence still yields frames.
    fn tick(&self, py: Python<'_>, now_s: f64) -> PyResult<Vec<PyFrame>> {
        guard(|| {
            finite("now_s", now_s)?;
            let out = self
                .locked(py, |s| s.tick(now_s))?
                .map_err(|e| pipeline_error(py, e))?;
            frames(py, out, self.basis.as_deref())
        })
    }

    /// The frame period on the frame clock (rounded to a microsecond), s.
    #[getter]
    fn period_s(&self, py: Python<'_>) -> PyResult<f64> {
        guard(|| Ok(self.locked(py, |s| s.period_us())? as f64 / 1e6))
    }

    /// Counters: samples, invalid, outliers, frames, fail_safe_frames, resyncs, plan_fallbacks.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let s = self.locked(py, |s| s.stats())?;
            let d = PyDict::new(py);
            d.set_item("samples", s.samples)?;
            d.set_item("invalid", s.invalid)?;
            d.set_item("outliers", s.outliers)?;
            d.set_item("frames", s.frames)?;
            d.set_item("fail_safe_frames", s.fail_safe_frames)?;
            d.set_item("resyncs", s.resyncs)?;
            d.set_item("plan_fallbacks", s.plan_fallbacks)?;
            Ok(d)
        })
    }

    /// Warnings since the last call (clock jumps, planning fallbacks), one line each.
    fn notices(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        guard(|| {
            Ok(self
                .locked(py, |s| s.take_notices())?
                .into_iter()
                .map(|n| match n {
                    Notice::Resync { from_s, to_s, frames } => format!(
                        "gaze clock jumped from {from_s} s to {to_s} s ({frames} frames due): one fail-safe frame, frame clock restarted, gaze history discarded"
                    ),
                    Notice::PlanFallback { gaze_deg, error } => format!(
                        "no certified adaptive profile for gaze {gaze_deg}°, baseline instead: {error}"
                    ),
                    Notice::Late { frames } => format!("output ran late, {frames} frame(s) skipped"),
                })
                .collect())
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        guard(|| {
            let (period_us, st) = self.locked(py, |s| (s.period_us(), s.stats()))?;
            Ok(format!(
                "<gaze_lidar.GazeStream preset={:?} mode={:?} period_s={} samples={} frames={} fail_safe_frames={}>",
                self.preset,
                self.mode,
                period_us as f64 / 1e6,
                st.samples,
                st.frames,
                st.fail_safe_frames
            ))
        })
    }
}

fn model_of(name: &str) -> PyResult<ModelKind> {
    name.parse().map_err(|e| value_error(format!("model: {e}")))
}

fn cloud_frame(frame: &str) -> PyResult<CloudFrame> {
    match frame {
        "carla" => Ok(CloudFrame::Carla),
        "iso8855" => Ok(CloudFrame::Iso8855),
        other => Err(value_error(format!(
            "frame: '{other}' is not one of carla, iso8855"
        ))),
    }
}

/// Something computed from a cloud's x, y, z, generic over the iterator so
/// that the per-point loop is monomorphized and inlined for each layout.
trait PointsVisitor: Sync {
    type Out: Send;
    fn visit<I: ExactSizeIterator<Item = [f64; 3]>>(&self, xyz: I) -> Self::Out;
}

struct KeepVisitor<'a> {
    certified: &'a CertifiedProfile,
    opts: &'a CloudOptions,
}

impl PointsVisitor for KeepVisitor<'_> {
    type Out = Result<Vec<bool>, gaze_lidar::pointcloud::CloudError>;
    fn visit<I: ExactSizeIterator<Item = [f64; 3]>>(&self, xyz: I) -> Self::Out {
        keep_mask(self.certified, xyz, self.opts)
    }
}

struct AzimuthVisitor(CloudFrame);

impl PointsVisitor for AzimuthVisitor {
    type Out = Vec<f64>;
    fn visit<I: ExactSizeIterator<Item = [f64; 3]>>(&self, xyz: I) -> Self::Out {
        xyz.map(|[x, y, _]| self.0.azimuth_deg(x, y)).collect()
    }
}

/// Hands `v` the x, y, z of a C-contiguous N×3 or N×4 float32/float64
/// array, with the GIL released. Any other layout is refused, never read:
/// `gaze_lidar`'s Python layer (`gaze_lidar._points.as_points`) brings every
/// array numpy can view as float (any dtype, byte order, memory order,
/// strides, structured x/y/z, CARLA's raw buffer) to one of these first.
fn with_points<'py, V: PointsVisitor>(points: &Bound<'py, PyAny>, v: V) -> PyResult<V::Out> {
    let py = points.py();
    let refused = || {
        let dtype = points
            .getattr("dtype")
            .map(|d| d.to_string())
            .unwrap_or_else(|_| points.get_type().to_string());
        let shape = points
            .getattr("shape")
            .and_then(|s| s.extract::<Vec<usize>>())
            .unwrap_or_default();
        value_error(format!(
            "points: the native layer takes a C-contiguous N×3 or N×4 float32/float64 array in native byte order (gaze_lidar.apply_profile and azimuth_deg convert any other), got dtype {dtype} and shape {shape:?}"
        ))
    };
    if let Ok(a) = points.extract::<PyReadonlyArray2<'py, f32>>() {
        let w = a.shape()[1];
        if !(w == 3 || w == 4) || !a.is_c_contiguous() {
            return Err(refused());
        }
        let flat = a.as_slice().map_err(|_| refused())?;
        return detached(py, || {
            v.visit(
                flat.chunks_exact(w)
                    .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])]),
            )
        });
    }
    if let Ok(a) = points.extract::<PyReadonlyArray2<'py, f64>>() {
        let w = a.shape()[1];
        if !(w == 3 || w == 4) || !a.is_c_contiguous() {
            return Err(refused());
        }
        let flat = a.as_slice().map_err(|_| refused())?;
        return detached(py, || {
            v.visit(flat.chunks_exact(w).map(|c| [c[0], c[1], c[2]]))
        });
    }
    Err(refused())
}

/// Azimuth of each point in the crate's convention (ISO 8855, degrees
/// counter-clockwise from ahead, in [0, 360)), as `apply_profile` sees it.
#[pyfunction]
#[pyo3(signature = (points, frame="carla"))]
fn azimuth_deg<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    frame: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let frame = cloud_frame(frame)?;
        let az = with_points(points, AzimuthVisitor(frame))?;
        Ok(PyArray1::from_vec(py, az))
    })
}

/// Which points of an N×4 (x, y, z, intensity) cloud a sensor running
/// `profile` would return: a numpy bool mask.
#[pyfunction]
#[pyo3(signature = (profile, points, *, rated_range_m, model="physical", fog_mor_m=None, seed=0, frame="carla", cloud_spin_rad_s=None))]
#[allow(clippy::too_many_arguments)]
fn apply_profile<'py>(
    py: Python<'py>,
    profile: &Bound<'py, PyProfile>,
    points: &Bound<'py, PyAny>,
    rated_range_m: f64,
    model: &str,
    fog_mor_m: Option<f64>,
    seed: i128,
    frame: &str,
    cloud_spin_rad_s: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    guard(|| {
        let opts = CloudOptions {
            rated_range_m,
            model: model_of(model)?,
            fog_mor_m,
            seed: seed_of(seed)?,
            frame: cloud_frame(frame)?,
            cloud_spin_rad_s,
        };
        let certified = &profile.get().inner;
        let mask = with_points(
            points,
            KeepVisitor {
                certified,
                opts: &opts,
            },
        )?;
        mask.map(|m| PyArray1::from_vec(py, m))
            .map_err(|e| value_error(e.to_string()))
    })
}

/// `model=`: one return model or a list of them.
#[derive(FromPyObject)]
enum Models {
    One(String),
    Many(Vec<String>),
}

const SIM_OPTIONS: &[&str] = &[
    "variants",
    "fog_pct",
    "detect",
    "bins",
    "preset",
    "scenario_toml",
    "optimizer_toml",
];

/// The paper's intersection experiment: the table rows (one dict per
/// model × variant × fog level).
#[pyfunction]
#[pyo3(
    signature = (model=Models::One("argus".to_owned()), trials=10, seed=1, **options),
    text_signature = "(model='argus', trials=10, seed=1, **options)"
)]
fn simulate<'py>(
    py: Python<'py>,
    model: Models,
    trials: i64,
    seed: i128,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let models = match model {
            Models::One(name) => vec![model_of(&name)?],
            Models::Many(names) => names.iter().map(|n| model_of(n)).collect::<PyResult<_>>()?,
        };
        if !(1..=100_000).contains(&trials) {
            return Err(value_error(format!(
                "trials: {trials} must lie in 1..=100000"
            )));
        }
        let mut config = SimConfig {
            models,
            trials: trials as usize,
            seed: seed_of(seed)?,
            ..SimConfig::default()
        };
        let mut preset_name: Option<String> = None;
        let mut optimizer = None;
        if let Some(opts) = options {
            for (k, v) in opts.iter() {
                let key: String = k.extract()?;
                let wrong = |what: &str| value_error(format!("{key}: expected {what}"));
                match key.as_str() {
                    "variants" => {
                        let names: Vec<String> =
                            v.extract().map_err(|_| wrong("a list of variant names"))?;
                        config.variants = names
                            .iter()
                            .map(|n| {
                                n.parse::<Variant>()
                                    .map_err(|e| value_error(format!("variants: {e}")))
                            })
                            .collect::<PyResult<_>>()?;
                    }
                    "fog_pct" => {
                        let levels: Vec<u32> = v
                            .extract()
                            .map_err(|_| wrong("a list of fog levels in %"))?;
                        for f in &levels {
                            if !FOG_LEVELS_PCT.contains(f) {
                                return Err(value_error(format!(
                                    "fog_pct: {f} is not one of the paper's levels 0, 25, 50"
                                )));
                            }
                        }
                        config.fog_pcts = levels;
                    }
                    "detect" => {
                        let s: String = v.extract().map_err(|_| wrong("'k/n'"))?;
                        let bad = || {
                            value_error(format!("detect: '{s}' is not k/n with 1 <= k <= n <= 100"))
                        };
                        let (k, n) = s.split_once('/').ok_or_else(bad)?;
                        let k: u32 = k.trim().parse().map_err(|_| bad())?;
                        let n: u32 = n.trim().parse().map_err(|_| bad())?;
                        if k == 0 || k > n || n > 100 {
                            return Err(bad());
                        }
                        config.detection = KOfN { k, n };
                    }
                    "bins" => {
                        let b: usize = v.extract().map_err(|_| wrong("an integer"))?;
                        config.bins = b;
                    }
                    "preset" => {
                        let name: String = v.extract().map_err(|_| wrong("a preset name"))?;
                        config.sensor = preset_of(&name)?;
                        preset_name = Some(name);
                    }
                    "scenario_toml" => {
                        let text: String = v.extract().map_err(|_| wrong("TOML text"))?;
                        config.scenario = Scenario::from_toml(&text, "scenario_toml")
                            .map_err(|e| value_error(e.to_string()))?;
                    }
                    "optimizer_toml" => {
                        use gaze_lidar::optimizer::OptimizerConfig;
                        let text: String = v.extract().map_err(|_| wrong("TOML text"))?;
                        let c = OptimizerConfig::from_toml(&text, "optimizer_toml")
                            .map_err(|e| opt_error(py, e))?;
                        optimizer = Some(c);
                    }
                    other => {
                        return Err(value_error(format!(
                            "{other}: unknown option (known: {})",
                            SIM_OPTIONS.join(", ")
                        )))
                    }
                }
            }
        }
        // As the CLI's --optimizer-config: the closed forms run on the
        // configuration's sensor, limits and driver model (with the levels
        // of the preset it names, `preset` replacing the file's).
        if let Some(mut c) = optimizer {
            if let Some(name) = preset_name {
                c.lidar.preset = Some(name);
            }
            let problem = c.problem().map_err(|e| opt_error(py, e))?;
            let named = c.preset().map_err(|e| opt_error(py, e))?;
            config.sensor =
                gaze_lidar::optimizer::figures::closed_form_basis(&problem, named.levels);
            config.optimizer = Some(problem);
        }
        if config.optimizer.is_some() && !config.variants.contains(&Variant::Optimized) {
            return Err(value_error(
                "optimizer_toml: configures the optimized variant: add 'optimized' to variants",
            ));
        }
        // On a pool of its own (fork-safe), Ctrl-C stopping it within a trial.
        let result = runtime::interruptible(py, true, move |cancel| {
            sim::run(&config, &|| cancel.check())
        })?
        .map_err(|e| {
            if e.is_input_error() {
                value_error(e.to_string())
            } else {
                Infeasible::new_err(e.to_string())
            }
        })?;
        let json = sim::table::render_json(&result).map_err(|e| value_error(e.to_string()))?;
        // The CLI's --trials-csv records, column for column.
        let trials = sim::table::render_trials_csv(&result)
            .map_err(|e| InternalError::new_err(format!("internal error: trials: {e}")))?;
        let out = PyDict::new(py);
        out.set_item("rows", json_value(py, &json)?.get_item("rows")?)?;
        out.set_item("trials_csv", trials)?;
        Ok(out.into_any())
    })
}

/// A recorded gaze file as columns (`gaze_lidar.read_gaze`).
#[pyfunction]
#[pyo3(signature = (path, format="jsonl"))]
fn read_gaze<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    format: &str,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let fmt = gaze_io::format_of(format).map_err(value_error)?;
        let origin = path.display().to_string();
        let bytes =
            std::fs::read(&path).map_err(|e| value_error(format!("path: {origin}: {e}")))?;
        let track = detached(py, || gaze_io::parse(&bytes, fmt, &origin))?
            .map_err(|e| pipeline_error(py, e.into()))?;
        let d = PyDict::new(py);
        d.set_item("t_s", PyArray1::from_vec(py, track.t_s))?;
        d.set_item("gaze_deg", PyArray1::from_vec(py, track.gaze_deg))?;
        d.set_item("valid", PyArray1::from_vec(py, track.valid))?;
        Ok(d)
    })
}

/// The native half of `gaze_lidar`: certified profiles, the checker, the
/// gaze stream, point-cloud filtering and the simulator (see `_native.pyi`).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Infeasible", py.get_type::<Infeasible>())?;
    m.add("Rejected", py.get_type::<Rejected>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyProfile>()?;
    m.add_class::<Verdict>()?;
    m.add_class::<PyFrame>()?;
    m.add_class::<PyGazeStream>()?;
    m.add_function(wrap_pyfunction!(profile, m)?)?;
    m.add_function(wrap_pyfunction!(optimize, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(apply_profile, m)?)?;
    m.add_function(wrap_pyfunction!(azimuth_deg, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(read_gaze, m)?)?;
    m.add(
        "GAZE_FORMATS",
        PyList::new(
            py,
            <gaze_lidar::gaze::Format as Named>::NAMES.iter().copied(),
        )?,
    )?;
    m.add_function(wrap_pyfunction!(replay::replay, m)?)?;
    m.add(
        "PRESETS",
        PyList::new(py, presets::PRESET_NAMES.iter().copied())?,
    )?;
    Ok(())
}
