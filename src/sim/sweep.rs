//! Sensitivity sweeps: the same run repeated over values of one scenario
//! key (`simulate --sweep KEY=V1,V2,…`), one table and one figure per key.
//!
//! A key is any numeric key of the scenario TOML, dotted for the `[carla]`
//! table (`speed_kmh`, `carla.mount_height_m`, `carla.tick_s`,
//! `carla.spawn_distance_m`, …), or an alias: `mount_height` =
//! `carla.mount_height_m`, `tick` = `carla.tick_s`, `spawn_distance` =
//! `carla.spawn_distance_m`, `grid_phase` = `carla.grid_phase_steps` (the
//! azimuth phase of CARLA's scan grid in fractions of a step; `carla`
//! geometry), `fog_threshold` = `argus_fog_threshold_scale` (a factor on
//! the `argus` return model's intensity thresholds in fog). Each value goes
//! through the scenario's own validation; the values of a sweep run
//! together ([`super::run_many`]), sharing what does not depend on them.

use std::fmt::Write;

use super::scene::{Scenario, ScenarioError};
use super::GridResult;

/// Aliases of the sweep keys.
pub const ALIASES: [(&str, &str); 5] = [
    ("mount_height", "carla.mount_height_m"),
    ("tick", "carla.tick_s"),
    ("spawn_distance", "carla.spawn_distance_m"),
    ("grid_phase", "carla.grid_phase_steps"),
    ("fog_threshold", "argus_fog_threshold_scale"),
];

/// The alias of a scenario key, or the key itself.
#[must_use]
pub fn short_name(key: &str) -> &str {
    ALIASES
        .iter()
        .find(|(_, k)| *k == key)
        .map_or(key, |(a, _)| *a)
}

/// The stem of a sweep's figure (`--plots`): `sweep_` and the key's short
/// name (its alias, or the key with `.` as `_`).
#[must_use]
pub fn figure_stem(sweep: &Sweep) -> String {
    format!("sweep_{}", short_name(&sweep.key).replace('.', "_"))
}

/// Most values in one sweep.
pub const MAX_VALUES: usize = 50;

/// A sweep: a key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The scenario key (aliases resolved).
    pub key: String,
    /// Values, in the order given.
    pub values: Vec<f64>,
}

/// A sweep specification is invalid. The messages name the specification,
/// not where it came from (the CLI prefixes its flag).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SweepError {
    /// Not `KEY=V1,V2,…`.
    #[error("'{0}' is not KEY=V1,V2,… (at least one number, at most 50)")]
    Syntax(String),
    /// The key is not a numeric scenario key.
    #[error("'{0}' is not a numeric scenario key (e.g. speed_kmh, carla.mount_height_m, mount_height, tick, spawn_distance, grid_phase, fog_threshold)")]
    Key(String),
    /// A value is rejected by the scenario.
    #[error("{key}={value}: {reason}")]
    Value {
        /// Key.
        key: String,
        /// Value.
        value: f64,
        /// The scenario's message.
        reason: String,
    },
}

/// Parses `KEY=V1,V2,…`.
pub fn parse(spec: &str) -> Result<Sweep, SweepError> {
    let bad = || SweepError::Syntax(spec.to_owned());
    let (key, values) = spec.split_once('=').ok_or_else(bad)?;
    let key = key.trim();
    let key = ALIASES
        .iter()
        .find(|(a, _)| *a == key)
        .map_or(key, |(_, k)| *k)
        .to_owned();
    let values = values
        .split(',')
        .map(|v| v.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(bad)?;
    if values.is_empty() || values.len() > MAX_VALUES || key.is_empty() {
        return Err(bad());
    }
    apply(&Scenario::default(), &key, values[0])?;
    Ok(Sweep { key, values })
}

/// The scenario with `key` set to `value` (validated).
pub fn apply(scenario: &Scenario, key: &str, value: f64) -> Result<Scenario, SweepError> {
    let bad_key = || SweepError::Key(key.to_owned());
    let mut doc = toml::Value::try_from(scenario).map_err(|_| bad_key())?;
    let mut slot = &mut doc;
    for part in key.split('.') {
        slot = slot
            .as_table_mut()
            .and_then(|t| t.get_mut(part))
            .ok_or_else(bad_key)?;
    }
    match slot {
        toml::Value::Float(x) => *x = value,
        toml::Value::Integer(i) => {
            if value.fract() != 0.0 || value.abs() > 1e15 {
                return Err(SweepError::Value {
                    key: key.to_owned(),
                    value,
                    reason: "this key takes an integer".to_owned(),
                });
            }
            *i = value as i64;
        }
        _ => return Err(bad_key()),
    }
    let text = toml::to_string(&doc).map_err(|_| bad_key())?;
    Scenario::from_toml(&text, "sweep").map_err(|e| SweepError::Value {
        key: key.to_owned(),
        value,
        reason: match e {
            ScenarioError::Toml { message, .. } => message,
            e => e.to_string(),
        },
    })
}

/// Why sweeping `key` cannot change a run of `config`, if it cannot: a
/// `[carla]` key (but the ego's yaw) outside the carla geometry, or the argus model's fog
/// threshold without the argus model. A sweep that changes nothing is
/// refused rather than tabulated as a flat line.
#[must_use]
pub fn inert(key: &str, config: &super::SimConfig) -> Option<String> {
    // The planar geometry reads one `[carla]` key: the ego's yaw (ARGUS's
    // density half-plane).
    if key.starts_with("carla.")
        && key != "carla.ego_yaw_deg"
        && config.geometry != super::Geometry::Carla
    {
        return Some(format!(
            "{key} is a parameter of the carla geometry: add --geometry carla (the planar geometry does not read it)"
        ));
    }
    if key == "argus_fog_threshold_scale" && !config.models.contains(&super::ModelKind::Argus) {
        return Some(format!(
            "{key} scales the argus return model's thresholds: add --model argus"
        ));
    }
    None
}

/// The text table of a sweep: one line per value × cell with the median
/// TTA, its interval, the modes and the paired test against the baseline.
#[must_use]
pub fn render_table(sweep: &Sweep, results: &[GridResult]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "sweep of {}", sweep.key);
    let _ = writeln!(
        s,
        "{:>10} {:<9} {:<11} {:>4} {:>8} {:>8} {:>13} {:<28} {:>7} {:>8}",
        "value",
        "model",
        "variant",
        "fog%",
        "detected",
        "TTA med",
        "TTA 95% CI",
        "TTA modes (s: share)",
        "Δ base",
        "p (W)"
    );
    for (value, r) in sweep.values.iter().zip(results) {
        for row in &r.rows {
            let st = &row.stats;
            let f2 = |x: Option<f64>| x.map_or_else(|| "—".to_owned(), |v| format!("{v:.2}"));
            let ci = match (st.tta_ci_lo_s, st.tta_ci_hi_s) {
                (Some(a), Some(b)) => format!("{a:.2}–{b:.2}"),
                _ => "—".to_owned(),
            };
            let modes = st
                .tta_modes
                .split(';')
                .filter_map(|m| {
                    let (t, sh) = m.split_once(':')?;
                    Some(format!(
                        "{}: {:.0}%",
                        t.parse::<f64>()
                            .ok()
                            .map_or_else(String::new, |t| format!("{t:.2}")),
                        sh.parse::<f64>().ok()? * 100.0
                    ))
                })
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "{:>10} {:<9} {:<11} {:>4} {:>8} {:>8} {:>13} {:<28} {:>7} {:>8}",
                crate::text::Num(*value).to_string(),
                row.model.name(),
                row.variant,
                row.fog_pct,
                format!("{}/{}", row.detected, row.trials),
                f2(row.tta_median_s),
                ci,
                if modes.is_empty() {
                    "—".to_owned()
                } else {
                    modes
                },
                st.vs_baseline_median_diff_s
                    .map_or_else(|| "—".to_owned(), |d| format!("{d:+.2}")),
                st.vs_baseline_wilcoxon_p
                    .map_or_else(|| "—".to_owned(), |p| format!("{p:.3}")),
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_keys_aliases_and_values() {
        let s = parse("tick=0.05,0.1").unwrap();
        assert_eq!(s.key, "carla.tick_s");
        assert_eq!(s.values, vec![0.05, 0.1]);
        assert_eq!(parse("speed_kmh=30").unwrap().key, "speed_kmh");
        assert_eq!(
            parse("grid_phase=0,0.5").unwrap().key,
            "carla.grid_phase_steps"
        );
        assert_eq!(
            parse("fog_threshold=0.5,2").unwrap().key,
            "argus_fog_threshold_scale"
        );
        assert_eq!(short_name("carla.grid_phase_steps"), "grid_phase");
        assert_eq!(short_name("speed_kmh"), "speed_kmh");
        // A grid phase is a fraction of one step; a threshold factor >= 0.
        let e = parse("grid_phase=1").unwrap_err().to_string();
        assert!(e.contains("carla.grid_phase_steps"), "{e}");
        let e = parse("fog_threshold=-1").unwrap_err().to_string();
        assert!(e.contains("argus_fog_threshold_scale"), "{e}");
        assert!(matches!(parse("speed_kmh"), Err(SweepError::Syntax(_))));
        assert!(matches!(parse("speed_kmh=a"), Err(SweepError::Syntax(_))));
        assert!(matches!(parse("nope=1"), Err(SweepError::Key(_))));
        assert!(matches!(parse("carla=1"), Err(SweepError::Key(_))));
        assert!(matches!(
            parse("speed_kmh=-5"),
            Err(SweepError::Value { .. })
        ));
    }

    #[test]
    fn keys_a_run_does_not_read_are_inert() {
        use crate::sim::{Geometry, ModelKind, SimConfig};
        let mut c = SimConfig {
            geometry: Geometry::Planar,
            models: vec![ModelKind::Physical],
            ..SimConfig::default()
        };
        for key in [
            "carla.tick_s",
            "carla.grid_phase_steps",
            "carla.mount_height_m",
        ] {
            let why = inert(key, &c).expect("inert");
            assert!(why.contains("--geometry carla"), "{why}");
        }
        assert_eq!(inert("carla.ego_yaw_deg", &c), None);
        assert_eq!(inert("speed_kmh", &c), None);
        let why = inert("argus_fog_threshold_scale", &c).expect("inert");
        assert!(why.contains("--model argus"), "{why}");
        c.models.push(ModelKind::Argus);
        assert_eq!(inert("argus_fog_threshold_scale", &c), None);
        c.geometry = Geometry::Carla;
        assert_eq!(inert("carla.tick_s", &c), None);
    }

    #[test]
    fn apply_sets_the_key_and_validates() {
        let s = apply(&Scenario::default(), "carla.mount_height_m", 2.9).unwrap();
        assert_eq!(s.carla.mount_height_m, 2.9);
        let s = apply(&Scenario::default(), "speed_kmh", 30.0).unwrap();
        assert_eq!(s.speed_kmh, 30.0);
        assert!(matches!(
            apply(&Scenario::default(), "speed_kmh", -1.0),
            Err(SweepError::Value { .. })
        ));
    }
}
