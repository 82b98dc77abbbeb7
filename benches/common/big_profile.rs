//! Large profiles for the `check` benchmark: the paper preset's closed-form
//! joint profile (gaze 90°, 360 bins plus region edges), each bin cut into
//! equal sub-bins so the whole has exactly `n` bins.
//!
//! - `Roughness::Smooth`: the sub-bins keep their bin's power and spin, so
//!   the physics (and the certificate) is the 360-bin profile's.
//! - `Roughness::Rough`: every sub-bin's power is scaled by a pseudo-random
//!   factor in [0.9, 1) and the spin inside each original bin follows
//!   `1 + 0.02·sin` over one full period (continuous, with in-bin acceleration
//!   everywhere), all spins then scaled so the frame period is the declared
//!   one: many distinct powers, so the envelope has a breakpoint at every bin.

use gaze_lidar::model::presets;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
use gaze_lidar::profile::{Bin, Profile};

/// How much structure the sub-bins carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(dead_code)]
pub enum Roughness {
    /// Sub-bins copy their bin.
    Smooth,
    /// Power ripple and in-bin acceleration on every sub-bin.
    Rough,
}

/// A splitmix64 step mapped to [0, 1).
fn unit(mut x: u64) -> f64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// The paper joint profile with exactly `n` bins (`n` ≥ 362).
pub fn big_profile(n: usize, roughness: Roughness) -> Profile {
    let mut p = build_profile(&presets::paper(), Mode::Joint, Some(90.0), 360)
        .expect("the paper preset plans");
    let base = std::mem::take(&mut p.bins);
    let l = base.len();
    assert!(n >= l, "n must be at least the base profile's {l} bins");
    let mut bins = Vec::with_capacity(n);
    for (i, b) in base.iter().enumerate() {
        let k = n * (i + 1) / l - n * i / l;
        let w = b.width_deg / k as f64;
        let spin_at = |j: usize| match roughness {
            Roughness::Smooth => b.spin_start_rad_s,
            Roughness::Rough => {
                b.spin_start_rad_s
                    * (1.0 + 0.02 * (std::f64::consts::TAU * j as f64 / k as f64).sin())
            }
        };
        for j in 0..k {
            let power_w = match roughness {
                Roughness::Smooth => b.power_w,
                Roughness::Rough => b.power_w * (1.0 - 0.1 * unit(bins.len() as u64)),
            };
            bins.push(Bin {
                start_deg: if j == 0 {
                    b.start_deg
                } else {
                    b.start_deg + j as f64 * w
                },
                width_deg: w,
                power_w,
                spin_start_rad_s: spin_at(j),
                spin_end_rad_s: if j + 1 == k {
                    spin_at(0)
                } else {
                    spin_at(j + 1)
                },
                region: b.region,
                dwell_s: None,
            });
        }
    }
    if roughness == Roughness::Rough {
        let period_s: f64 = bins.iter().map(Bin::dwell_time_s).sum();
        let scale = period_s * p.frame_rate_hz;
        for b in &mut bins {
            b.spin_start_rad_s *= scale;
            b.spin_end_rad_s *= scale;
        }
    }
    p.bins = bins;
    p
}
