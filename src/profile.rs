//! The scan profile and its interchange formats. The `gaze-lidar/profile@1`
//! types and JSON belong to the trusted core ([`gaze_lidar_core::profile`],
//! re-exported here); this module adds the CSV export and atomic file output.

use serde::Serialize;
use std::io::Write;
use std::path::Path;

pub use gaze_lidar_core::profile::*;

fn csv_err(e: csv::Error) -> IoError {
    IoError::Encoding {
        format: "csv",
        message: e.to_string(),
    }
}

/// CSV, one row per bin: the per-bin fields of profile@1.
pub fn to_csv(profile: &Profile) -> Result<String, IoError> {
    #[derive(Serialize)]
    struct Row<'a> {
        start_deg: f64,
        width_deg: f64,
        power_w: f64,
        spin_start_rad_s: f64,
        spin_end_rad_s: f64,
        region: Option<&'a str>,
        dwell_s: f64,
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    for b in &profile.bins {
        w.serialize(Row {
            start_deg: b.start_deg,
            width_deg: b.width_deg,
            power_w: b.power_w,
            spin_start_rad_s: b.spin_start_rad_s,
            spin_end_rad_s: b.spin_end_rad_s,
            region: b.region.map(|r| match r {
                Region::Rof => "rof",
                Region::Roi => "roi",
            }),
            dwell_s: b.dwell_time_s(),
        })
        .map_err(csv_err)?;
    }
    let bytes = w.into_inner().map_err(|e| IoError::File {
        path: "<csv buffer>".into(),
        source: e.into_error(),
    })?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Writes `contents` to `path` atomically: a temporary file in the same
/// folder, then a rename, so a failure never leaves a partial file.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), IoError> {
    let err = |source| IoError::File {
        path: path.display().to_string(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    // Ordinary output files: readable by others (tempfile defaults to 0600).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(err)?;
    tmp.write_all(contents).map_err(err)?;
    tmp.flush().map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}
