//! Gaze input formats. Every parser turns one line into a [`GazeSample`] in
//! the vehicle frame (azimuth CCW from straight ahead, degrees) or an error
//! naming the field; callers add the line number.
//!
//! - `jsonl`: `{"t_s": 1.23, "gaze_deg": 87.5, "valid": true}` (`valid`
//!   optional, default true; `gaze_deg` null → invalid).
//! - `csv`: header `t_s,gaze_deg[,valid]`.
//! - `varjo`: Varjo Base gaze recordings (CSV). Uses `raw_timestamp` (ns),
//!   `status` (2 = valid; 0 invalid, 1 adjusting), the head-relative unit
//!   vector `gaze_forward_x/y/z` (HMD axes: x right, y up, z forward) and
//!   the head orientation quaternion `HMD_rotation_x/y/z/w` (same axes,
//!   head in the vehicle frame). Azimuth = atan2(−x_w, z_w) of the rotated
//!   gaze (vehicle x forward = HMD z, y left = −HMD x). Assumption to check
//!   against a vendor recording: the simulator's world frame is the vehicle
//!   frame (ego stopped), as in the paper's setup.
//! - `neon`: Pupil Neon `gaze.csv`: `timestamp [ns]`, `azimuth [deg]`
//!   (positive to the right of the scene camera), `worn` (1 = on the head).
//!   Head-relative: the head is assumed to face straight ahead (no IMU
//!   fusion), so gaze = −azimuth.

use serde::Deserialize;
use std::collections::HashMap;
use thiserror::Error;

/// One gaze sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GazeSample {
    /// Timestamp, s (monotonic within a recording).
    pub t_s: f64,
    /// Gaze azimuth, degrees (meaningless when `!valid`).
    pub gaze_deg: f64,
    /// Whether the tracker had the eyes.
    pub valid: bool,
}

impl GazeSample {
    /// Whether the sample carries a usable gaze: the tracker's flag, a
    /// finite azimuth and |gaze| ≤ [`MAX_ABS_GAZE_DEG`](crate::model::acuity::MAX_ABS_GAZE_DEG).
    #[must_use]
    pub fn usable(&self) -> bool {
        self.valid
            && self.gaze_deg.is_finite()
            && self.gaze_deg.abs() <= crate::model::acuity::MAX_ABS_GAZE_DEG
    }
}

/// Input formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// JSON lines.
    Jsonl,
    /// CSV with `t_s,gaze_deg[,valid]`.
    Csv,
    /// Varjo Base gaze CSV.
    Varjo,
    /// Pupil Neon `gaze.csv`.
    Neon,
}

crate::names::named_enum!(Format {
    Jsonl => "jsonl", "JSON lines";
    Csv => "csv", "CSV with `t_s,gaze_deg[,valid]`";
    Varjo => "varjo", "Varjo Base gaze CSV";
    Neon => "neon", "Pupil Neon `gaze.csv`";
});

/// A line that is not a sample.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LineError {
    /// Malformed JSON (serde names the field).
    #[error("{0}")]
    Json(String),
    /// A CSV field is missing or unparsable.
    #[error("field '{field}': {reason}")]
    Field {
        /// Column name.
        field: String,
        /// Why.
        reason: String,
    },
    /// A CSV row does not have the header's number of fields.
    #[error("row: {0}")]
    Row(String),
    /// A field that is present but not a number (`column`: 1-based
    /// character position of the field in its line).
    #[error("column {column}: field '{field}': {reason}")]
    Value {
        /// 1-based column of the field's first character.
        column: usize,
        /// Column name.
        field: String,
        /// Why.
        reason: String,
    },
    /// The header lacks a required column.
    #[error("header: missing column '{0}'")]
    Header(String),
    /// The header names a column twice (which one would be read?).
    #[error("header: column '{0}' appears twice")]
    DuplicateColumn(String),
    /// The line's bytes are not a text line at all (not UTF-8, too long,
    /// a byte-order mark).
    #[error("{0}")]
    Bytes(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonSample {
    t_s: f64,
    gaze_deg: Option<f64>,
    #[serde(default)]
    valid: Option<bool>,
}

/// A line parser with the state CSV formats need (the header).
#[derive(Debug, Clone)]
pub struct Parser {
    format: Format,
    columns: Option<HashMap<String, usize>>,
    header_fields: usize,
}

impl Parser {
    /// A parser for `format`.
    #[must_use]
    pub fn new(format: Format) -> Self {
        Self {
            format,
            columns: None,
            header_fields: 0,
        }
    }

    /// Parses one line: `Ok(None)` for a header or blank line. A sample
    /// whose gaze is not [usable](GazeSample::usable) comes back invalid.
    pub fn line(&mut self, line: &str) -> Result<Option<GazeSample>, LineError> {
        Ok(self.parse(line)?.map(|mut s| {
            s.valid = s.usable();
            s
        }))
    }

    fn parse(&mut self, line: &str) -> Result<Option<GazeSample>, LineError> {
        let line = line.trim_end_matches(['\r', '\n']);
        if line.trim().is_empty() {
            return Ok(None);
        }
        match self.format {
            Format::Jsonl => {
                let s: JsonSample =
                    serde_json::from_str(line).map_err(|e| LineError::Json(e.to_string()))?;
                if !s.t_s.is_finite() {
                    return Err(LineError::Field {
                        field: "t_s".into(),
                        reason: "not a finite time".into(),
                    });
                }
                let g = s.gaze_deg.unwrap_or(f64::NAN);
                Ok(Some(GazeSample {
                    t_s: s.t_s,
                    gaze_deg: g,
                    valid: s.valid.unwrap_or(true) && g.is_finite(),
                }))
            }
            Format::Csv | Format::Varjo | Format::Neon => self.csv_line(line),
        }
    }

    fn csv_line(&mut self, line: &str) -> Result<Option<GazeSample>, LineError> {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let Some(cols) = &self.columns else {
            let mut cols: HashMap<String, usize> = HashMap::with_capacity(fields.len());
            for (i, f) in fields.iter().enumerate() {
                if cols.insert((*f).to_owned(), i).is_some() {
                    return Err(LineError::DuplicateColumn((*f).to_owned()));
                }
            }
            let required: &[&str] = match self.format {
                Format::Csv => &["t_s", "gaze_deg"],
                Format::Varjo => &[
                    "raw_timestamp",
                    "status",
                    "gaze_forward_x",
                    "gaze_forward_y",
                    "gaze_forward_z",
                    "HMD_rotation_x",
                    "HMD_rotation_y",
                    "HMD_rotation_z",
                    "HMD_rotation_w",
                ],
                Format::Neon => &["timestamp [ns]", "azimuth [deg]", "worn"],
                Format::Jsonl => &[],
            };
            if let Some(missing) = required.iter().find(|r| !cols.contains_key(**r)) {
                return Err(LineError::Header((*missing).to_owned()));
            }
            self.columns = Some(cols);
            self.header_fields = fields.len();
            return Ok(None);
        };
        if fields.len() != self.header_fields {
            // A row cut short (a truncated file) or run together with the next.
            let missing = cols
                .iter()
                .filter(|(_, &i)| i >= fields.len())
                .min_by_key(|(_, &i)| i)
                .map_or_else(String::new, |(name, _)| format!(" ('{name}' missing)"));
            return Err(LineError::Row(format!(
                "{} fields where the header has {}{missing}: truncated or malformed row",
                fields.len(),
                self.header_fields
            )));
        }
        // 1-based character column of field `i` (its first non-blank character).
        let column = |i: usize| -> usize {
            let mut col = 1;
            for (k, raw) in line.split(',').enumerate() {
                if k == i {
                    return col + raw.chars().take_while(|c| c.is_whitespace()).count();
                }
                col += raw.chars().count() + 1;
            }
            col
        };
        let get = |name: &str| -> Result<f64, LineError> {
            let i = cols[name];
            let raw = fields.get(i).ok_or_else(|| LineError::Field {
                field: name.into(),
                reason: "missing".into(),
            })?;
            raw.parse::<f64>().map_err(|_| LineError::Value {
                column: column(i),
                field: name.into(),
                reason: format!("'{raw}' is not a number"),
            })
        };
        // A gaze value: a number, `NaN` or an empty field (the tracker had
        // no gaze: an invalid sample); anything else is a malformed row.
        let gaze = |name: &str| -> Result<f64, LineError> {
            if fields.get(cols[name]).is_some_and(|f| f.is_empty()) {
                Ok(f64::NAN)
            } else {
                get(name)
            }
        };
        let time = |name: &str, scale: f64| -> Result<f64, LineError> {
            let t = get(name)? * scale;
            if t.is_finite() {
                Ok(t)
            } else {
                Err(LineError::Field {
                    field: name.into(),
                    reason: "not a finite time".into(),
                })
            }
        };
        match self.format {
            Format::Csv => {
                let t_s = time("t_s", 1.0)?;
                let g = gaze("gaze_deg")?;
                let valid = match cols.get("valid").and_then(|&i| fields.get(i)) {
                    None => true,
                    Some(v) => match v.to_ascii_lowercase().as_str() {
                        "true" | "1" => true,
                        "false" | "0" => false,
                        other => {
                            return Err(LineError::Field {
                                field: "valid".into(),
                                reason: format!("'{other}' is not true/false"),
                            })
                        }
                    },
                };
                Ok(Some(GazeSample {
                    t_s,
                    gaze_deg: g,
                    valid: valid && g.is_finite(),
                }))
            }
            Format::Varjo => {
                let t_s = time("raw_timestamp", 1e-9)?;
                let status = get("status")?;
                let g = [
                    get("gaze_forward_x")?,
                    get("gaze_forward_y")?,
                    get("gaze_forward_z")?,
                ];
                let q = [
                    get("HMD_rotation_x")?,
                    get("HMD_rotation_y")?,
                    get("HMD_rotation_z")?,
                    get("HMD_rotation_w")?,
                ];
                let w = rotate(q, g);
                let az = (-w[0]).atan2(w[2]).to_degrees();
                let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                let valid = status == 2.0 && az.is_finite() && norm > 0.5;
                Ok(Some(GazeSample {
                    t_s,
                    gaze_deg: az,
                    valid,
                }))
            }
            Format::Neon => {
                let t_s = time("timestamp [ns]", 1e-9)?;
                let az = gaze("azimuth [deg]")?;
                let worn = get("worn")?;
                Ok(Some(GazeSample {
                    t_s,
                    gaze_deg: -az,
                    valid: worn >= 0.5 && az.is_finite(),
                }))
            }
            Format::Jsonl => Ok(None),
        }
    }
}

/// Rotates vector `v` (HMD frame) by the head orientation `q = (x, y, z, w)`
/// (normalised first; a zero or non-finite quaternion gives NaN), with
/// nalgebra's unit quaternion: the frame change from head to vehicle.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    use nalgebra::{Quaternion, UnitQuaternion, Vector3};
    let [x, y, z, w] = q;
    let raw = Quaternion::new(w, x, y, z);
    let n = raw.norm();
    if n.is_nan() || n <= 0.0 || !n.is_finite() {
        return [f64::NAN; 3];
    }
    let head = UnitQuaternion::from_quaternion(raw);
    let out = head * Vector3::new(v[0], v[1], v[2]);
    [out.x, out.y, out.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_yaw_left_turns_gaze_left() {
        // Head yawed 90° to the left about the up axis (HMD y); HMD axes are
        // left-handed-like (x right, z forward): a left turn maps forward (0,0,1) to (−1,0,0).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let w = rotate([0.0, -h, 0.0, h], [0.0, 0.0, 1.0]);
        assert!((w[0] + 1.0).abs() < 1e-12 && w[2].abs() < 1e-12, "{w:?}");
        assert!(((-w[0]).atan2(w[2]).to_degrees() - 90.0).abs() < 1e-9);
    }

    #[test]
    fn truncated_csv_rows_are_rejected_naming_the_field() {
        let mut p = Parser::new(Format::Neon);
        let header = "section id,recording id,timestamp [ns],gaze x [px],gaze y [px],worn,fixation id,blink id,azimuth [deg],elevation [deg]";
        assert!(p.line(header).unwrap().is_none());
        assert!(
            p.line("s1,r1,1700000000000000000,800,600,1,1,,10.000,-2.0")
                .unwrap()
                .unwrap()
                .valid
        );
        let e = p.line("s1,r1,1700000000005000000,800,6").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("5 fields where the header has 10"), "{msg}");
        assert!(msg.contains("'worn' missing"), "{msg}");
        let mut p = Parser::new(Format::Csv);
        p.line("t_s,gaze_deg,valid").unwrap();
        assert!(p.line("0.1,90").is_err());
        assert!(!p.line("0.1,1e300,true").unwrap().unwrap().valid);
    }

    #[test]
    fn a_malformed_gaze_is_an_error_an_absent_one_an_invalid_sample() {
        let mut p = Parser::new(Format::Csv);
        p.line("t_s,gaze_deg,valid").unwrap();
        let e = p.line("0.1,abc,true").unwrap_err();
        assert_eq!(
            e,
            LineError::Value {
                column: 5,
                field: "gaze_deg".into(),
                reason: "'abc' is not a number".into()
            }
        );
        assert!(!p.line("0.1,,true").unwrap().unwrap().valid);
        assert!(!p.line("0.1,NaN,true").unwrap().unwrap().valid);
        assert!(!p.line("0.1,10,false").unwrap().unwrap().valid);
        assert!(p.line("0.1, 10 ,true").unwrap().unwrap().valid);
        let mut p = Parser::new(Format::Neon);
        p.line("timestamp [ns],azimuth [deg],worn").unwrap();
        assert!(matches!(
            p.line("1700000000000000000,x1,1"),
            Err(LineError::Value { column: 21, .. })
        ));
        assert!(!p.line("1700000000000000000,,1").unwrap().unwrap().valid);
        let mut p = Parser::new(Format::Neon);
        assert_eq!(
            p.line("timestamp [ns],azimuth [deg],worn,azimuth [deg]"),
            Err(LineError::DuplicateColumn("azimuth [deg]".into()))
        );
    }

    #[test]
    fn jsonl_validity_rules() {
        let mut p = Parser::new(Format::Jsonl);
        assert!(
            !p.line(r#"{"t_s": 0.1, "gaze_deg": 1e300}"#)
                .unwrap()
                .unwrap()
                .valid,
            "absurd gaze is an invalid sample"
        );
        let mut p = Parser::new(Format::Jsonl);
        assert!(
            p.line(r#"{"t_s": 0.1, "gaze_deg": 90}"#)
                .unwrap()
                .unwrap()
                .valid
        );
        assert!(
            !p.line(r#"{"t_s": 0.1, "gaze_deg": null}"#)
                .unwrap()
                .unwrap()
                .valid
        );
        assert!(
            !p.line(r#"{"t_s": 0.1, "gaze_deg": 90, "valid": false}"#)
                .unwrap()
                .unwrap()
                .valid
        );
        assert!(p.line(r#"{"t_s": 0.1, "gaze": 90}"#).is_err());
        assert!(p.line("").unwrap().is_none());
    }
}
