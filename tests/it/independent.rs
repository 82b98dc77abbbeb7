//! An independent re-check of a profile's declared limits, for tests that
//! would otherwise re-run `checker::certify` on a profile the same checker
//! has just accepted (an assertion that cannot fail).
//!
//! Written from the profile@1 definition (README, "The profile format"; `specs/`), sharing no
//! code with `gaze_lidar::checker`: its own kinematics (constant angular
//! acceleration inside a bin: dwell = 2·Δθ/(ω₀+ω₁), α = (ω₁²−ω₀²)/(2·Δθ)),
//! its own sums and its own tolerance. Eye safety is the business of the
//! brute-force reference (`crates/core/src/testing/reference.rs`), see [`reference_ratio`].

#![allow(dead_code)]

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::profile::Profile;

/// Relative slack for float sums (the checker's own is 1e-9; this is
/// looser on purpose so that only a real violation trips it).
const SLACK: f64 = 1e-8;

fn le(value: f64, limit: f64) -> bool {
    value <= limit + SLACK * limit.abs().max(1e-300)
}

/// Every declared limit the profile breaks, recomputed from its numbers;
/// empty when it is within all of them.
pub fn recheck(p: &Profile) -> Vec<String> {
    let mut out = Vec::new();
    let l = &p.limits;
    let n = p.bins.len();
    if n == 0 {
        return vec!["no bins".into()];
    }
    let mut edge = 0.0;
    let (mut period_s, mut angle_energy, mut energy_j) = (0.0, 0.0, 0.0);
    for (i, b) in p.bins.iter().enumerate() {
        if (b.start_deg - edge).abs() > 1e-6 {
            out.push(format!("bin {i}: starts at {} not {edge}", b.start_deg));
        }
        edge = b.start_deg + b.width_deg;
        let (w0, w1) = (b.spin_start_rad_s, b.spin_end_rad_s);
        if !(b.width_deg > 0.0 && w0 > 0.0 && w1 > 0.0) {
            out.push(format!("bin {i}: non-positive width or spin"));
            continue;
        }
        let dth = b.width_deg.to_radians();
        let dwell = 2.0 * dth / (w0 + w1);
        period_s += dwell;
        angle_energy += b.power_w * b.width_deg;
        energy_j += b.power_w * dwell;
        if !le(b.power_w, l.power_w_max) || !le(l.power_w_min, b.power_w) {
            out.push(format!("bin {i}: power {} W outside the limits", b.power_w));
        }
        if !le(w0.max(w1), l.spin_rad_s_max) || !le(l.spin_rad_s_min, w0.min(w1)) {
            out.push(format!("bin {i}: spin {w0}..{w1} rad/s outside the limits"));
        }
        if let Some(a_max) = l.spin_accel_rad_s2_max {
            let a = ((w1 * w1 - w0 * w0) / (2.0 * dth)).abs();
            if !le(a, a_max) {
                out.push(format!("bin {i}: |accel| {a} rad/s² > {a_max}"));
            }
            let next = &p.bins[(i + 1) % n];
            if (next.spin_start_rad_s - w1).abs() > SLACK * w1.max(1.0) {
                out.push(format!("bin {i}: spin steps to the next bin"));
            }
        }
        if let (Some(s_max), true) = (l.power_slew_w_per_deg_max, n > 1) {
            let next = &p.bins[(i + 1) % n];
            let s = (next.power_w - b.power_w).abs() / (0.5 * (b.width_deg + next.width_deg));
            if !le(s, s_max) {
                out.push(format!("bin {i}: power slew {s} W/° > {s_max}"));
            }
        }
    }
    if (edge - 360.0).abs() > 1e-6 {
        out.push(format!("bins end at {edge}°, not 360°"));
    }
    let f = p.frame_rate_hz;
    if (period_s * f - 1.0).abs() > SLACK {
        out.push(format!(
            "turn takes {period_s} s, frame rate says {}",
            1.0 / f
        ));
    }
    let average_w = match p.power_accounting {
        PowerAccounting::Angle => angle_energy / 360.0,
        PowerAccounting::Time => energy_j * f,
    };
    if !le(average_w, p.average_power_w) {
        out.push(format!(
            "average power {average_w} W > budget {} W",
            p.average_power_w
        ));
    }
    out
}

/// Every integer limit a firmware table breaks, restated from the
/// firmware@1 definition in `u128` (frame = Σ ticks, dwell bounds, codes,
/// energy budget, every cyclic window sum); empty when within all of them.
pub fn recheck_table(t: &gaze_lidar::firmware::FirmwareTable) -> Vec<String> {
    let mut out = Vec::new();
    let n = t.bins.len();
    if n == 0 {
        return vec!["no bins".into()];
    }
    let l = &t.limits;
    let ticks: u128 = t.bins.iter().map(|b| b.dwell_ticks as u128).sum();
    if ticks != t.frame_ticks as u128 {
        out.push(format!("Σ ticks {ticks} != frame_ticks {}", t.frame_ticks));
    }
    let width: u128 = t.bins.iter().map(|b| b.width_mdeg as u128).sum();
    if width != 360_000 {
        out.push(format!("Σ width {width} mdeg != 360000"));
    }
    let mut energy: u128 = 0;
    for (i, b) in t.bins.iter().enumerate() {
        if b.dwell_ticks < b.dwell_ticks_min || b.dwell_ticks > b.dwell_ticks_max {
            out.push(format!(
                "bin {i}: dwell {} ticks outside its bounds",
                b.dwell_ticks
            ));
        }
        if b.power_code > b.power_code_cap
            || b.power_code > l.power_code_max
            || b.power_code < l.power_code_min
        {
            out.push(format!("bin {i}: code {} outside its limits", b.power_code));
        }
        let weight = match t.power_accounting {
            PowerAccounting::Angle => b.width_mdeg as u128,
            PowerAccounting::Time => b.dwell_ticks as u128,
        };
        energy += b.power_code as u128 * weight;
    }
    if energy > l.energy_budget as u128 {
        out.push(format!("energy {energy} > budget {}", l.energy_budget));
    }
    let w = (l.window_bins as usize).min(n);
    for s in 0..n {
        let e: u128 = (0..w)
            .map(|k| {
                let b = &t.bins[(s + k) % n];
                b.power_code as u128 * b.dwell_ticks as u128
            })
            .sum();
        if e > l.window_energy_max as u128 {
            out.push(format!("window at {s}: {e} > {}", l.window_energy_max));
        }
    }
    out
}
