//! Results as plain records: dicts of columns and (when pandas is
//! installed) DataFrames. pandas is optional: only `to_pandas` imports it.

use numpy::PyArray1;
use pyo3::exceptions::PyImportError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::PyProfile;

/// `import pandas`, or an ImportError saying what needs it and how to get it.
pub fn pandas<'py>(py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyModule>> {
    py.import("pandas").map_err(|_| {
        PyImportError::new_err(format!(
            "{what} needs pandas, which is not installed: `pip install pandas` (to_dict() gives the same data without it)"
        ))
    })
}

/// A profile's bins as columns; range_m and points_per_deg per bin (the
/// figures' per-bin values, `planner::figures`) when its preset is known.
pub fn profile_columns<'py>(py: Python<'py>, p: &PyProfile) -> PyResult<Bound<'py, PyDict>> {
    use gaze_lidar::planner::figures::{points_per_deg, range_m};
    use gaze_lidar::profile::Region;
    let prof = p.inner.profile();
    let bins = &prof.bins;
    let col = |f: &dyn Fn(&gaze_lidar::profile::Bin) -> f64| {
        PyArray1::from_vec(py, bins.iter().map(f).collect())
    };
    let d = PyDict::new(py);
    d.set_item("start_deg", col(&|b| b.start_deg))?;
    d.set_item("width_deg", col(&|b| b.width_deg))?;
    d.set_item("power_w", col(&|b| b.power_w))?;
    d.set_item("spin_start_rad_s", col(&|b| b.spin_start_rad_s))?;
    d.set_item("spin_end_rad_s", col(&|b| b.spin_end_rad_s))?;
    d.set_item("dwell_s", col(&|b| b.dwell_time_s()))?;
    d.set_item(
        "in_rof",
        PyArray1::from_vec(
            py,
            bins.iter().map(|b| b.region == Some(Region::Rof)).collect(),
        ),
    )?;
    if let Some(name) = &p.basis {
        let preset = crate::preset_of(name)?;
        d.set_item("range_m", col(&|b| range_m(&preset.lidar, b.power_w)))?;
        d.set_item(
            "points_per_deg",
            col(&|b| points_per_deg(prof.pulse_rate_hz, b)),
        )?;
    }
    Ok(d)
}
