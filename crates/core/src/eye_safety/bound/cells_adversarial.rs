//! Adversarial tests of the sweep's curved-cell bounds
//! (`cells.rs`): a generator aimed at what the midpoint fix touched —
//! many bins, spins near 0 at one edge (extreme acceleration), `h` equal
//! to (or half of, or a hair off) a bin width so that cuts coincide,
//! pulse periods `Δ` equal to a bin's duration or to the time a pass edge
//! needs to cross a bin, so envelope breakpoints land on cuts. Each cell's
//! sweep figures (`tau_ub`, `env_ub`, `e_ub`, `single_ub`, `tau_lb`) are
//! compared with [`Cells::exact`] and both with a dense scan of `τ(φ)` and
//! `E(φ)` (`time_at`, `env.integral_to`), as
//! `cell_figures_bound_a_dense_scan` does. A unit test: the cells are
//! `pub(super)` internals. Cases: `PROPTEST_CASES` (default 64 here, fast).

use super::cells::with_cells;
use super::seg::{seg, Seg};
use proptest::prelude::*;

/// A bin: relative width, power, start spin.
type BinSpec = (f64, f64, f64);

fn spin() -> impl Strategy<Value = f64> {
    prop_oneof![
        2.0f64..200.0,
        0.005f64..1.0,
        1e-3f64..2e-3,
        Just(1.0),
        Just(10.0),
    ]
}

fn bins() -> impl Strategy<Value = Vec<BinSpec>> {
    proptest::collection::vec(
        (
            prop_oneof![0.2f64..1.0, 1e-3f64..1e-2],
            prop_oneof![0.0f64..5e-3, Just(0.0), Just(5e-3)],
            spin(),
        ),
        2..40,
    )
}

fn segs_of(bins: &[BinSpec]) -> Vec<Seg> {
    let total: f64 = bins.iter().map(|b| b.0).sum();
    let n = bins.len();
    let mut start = 0.0;
    (0..n)
        .map(|i| {
            let (w, p, w0) = bins[i];
            let width = 360.0 * w / total;
            let s = seg(start, width, p, w0, bins[(i + 1) % n].2);
            start += width;
            s
        })
        .collect()
}

/// `h`: free, or tied to bin `k`'s width (equal, half, or one part in
/// 1e9 off either way).
fn h_of(segs: &[Seg], choice: (u8, usize, f64)) -> f64 {
    let w = segs[choice.1 % segs.len()].width_deg;
    let h = match choice.0 % 6 {
        0 => choice.2,
        1 => w,
        2 => 0.5 * w,
        3 => w * (1.0 + 1e-9),
        4 => 0.5 * w * (1.0 - 1e-9),
        _ => w * (1.0 - 1e-12),
    };
    h.clamp(1e-3, 30.0)
}

/// `f_p`: free, or `1/Δ` with `Δ` a bin's duration, or the time the head
/// takes over `2h` in bin `k` (a cell's width there).
fn f_p_of(segs: &[Seg], h: f64, choice: (u8, usize, f64)) -> f64 {
    let s = &segs[choice.1 % segs.len()];
    let dwell = 2.0 * s.width_deg.to_radians() / (s.spin_start_rad_s + s.spin_end_rad_s);
    let cross = 2.0 * (2.0 * h).to_radians() / (s.spin_start_rad_s + s.spin_end_rad_s);
    let f = match choice.0 % 4 {
        0 => choice.2,
        1 => 1.0 / dwell,
        2 => 1.0 / cross,
        _ => 1.0 / (0.5 * dwell),
    };
    f.clamp(1.0, 1e6)
}

fn check(segs: &[Seg], h: f64, f_p: f64, scan: u32) -> Result<(), TestCaseError> {
    let delta = 1.0 / f_p;
    with_cells(segs, h, f_p, |cells| {
        // Times are absolute (up to a period, thousands of s when a spin
        // is near 0): `E` is a difference of prefix integrals at float
        // times, each a few ulps of `t` off, so the scan and the exact
        // evaluation may differ by `P_max` times those ulps (first run:
        // 5.7e-16 J on 5.6e-6 J, all power in one bin, period ≈ 1e3 s).
        let p_max = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
        let t_ulps = 8.0 * f64::EPSILON * (cells.tl.period_s() + delta) * p_max;
        // Azimuths are absolute too: an ulp of `φ` (~720°) moves a pass
        // edge by `ulp/ω` in time, large where the spin nears 0 (second
        // run: 5.4e-17 J = `P`·1.7e-14 s at a cut where `t(φ + h) + Δ`
        // meets a bin start, spin ≈ 0.05 rad/s there).
        let w_min = segs
            .iter()
            .map(|s| s.spin_start_rad_s.min(s.spin_end_rad_s))
            .fold(f64::INFINITY, f64::min);
        let a_ulps = 8.0 * f64::EPSILON * 720f64.to_radians() / w_min * p_max;
        let tol_e = 1e-12 * cells.env.total_j() + t_ulps + a_ulps;
        // The same two for `τ` (third run: 9.9e-13 s on 0.0236 s).
        let tol_t = 1e-12 * cells.tl.period_s()
            + 8.0 * f64::EPSILON * (cells.tl.period_s() + 720f64.to_radians() / w_min);
        for c in 0..cells.len() {
            let x = cells.exact(c);
            let row = cells.rows[c];
            prop_assert!(row.tau_ub >= x.tau_s, "cell {c}: {row:?} {x:?}");
            prop_assert!(row.env_ub >= x.e_env, "cell {c}: {row:?} {x:?}");
            prop_assert!(row.e_ub >= x.e.0, "cell {c}: {row:?} {x:?}");
            prop_assert!(row.single_ub >= x.single, "cell {c}: {row:?} {x:?}");
            prop_assert!(row.tau_lb <= x.tau_min_s, "cell {c}: {row:?} {x:?}");
            let (u, v) = (cells.cut(c), cells.cut(c + 1));
            for k in 0..=scan {
                let phi = u + (v - u) * f64::from(k) / f64::from(scan);
                let t_lo = cells.time_at(phi - h);
                let t_hi = cells.time_at(phi + h);
                let e = cells.env.integral_to(t_hi + delta) - cells.env.integral_to(t_lo);
                let tau = t_hi - t_lo;
                prop_assert!(x.tau_s >= tau - tol_t, "cell {c} at {phi}: {x:?} τ {tau}");
                prop_assert!(
                    x.tau_min_s <= tau + tol_t,
                    "cell {c} at {phi}: {x:?} τ {tau}"
                );
                prop_assert!(x.e_env >= e - tol_e, "cell {c} at {phi}: {x:?} E {e}");
                prop_assert!(row.env_ub >= e - tol_e, "cell {c} at {phi}: {row:?} E {e}");
                prop_assert!(
                    row.tau_ub >= tau - tol_t,
                    "cell {c} at {phi}: {row:?} τ {tau}"
                );
                prop_assert!(
                    row.tau_lb <= tau + tol_t,
                    "cell {c} at {phi}: {row:?} τ {tau}"
                );
            }
        }
        Ok(())
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64)
    ))]

    /// The stress generator above; see the module docs.
    #[test]
    fn curved_cells_bound_a_dense_scan_under_stress(
        bins in bins(),
        h_choice in (0u8..6, 0usize..64, 0.05f64..30.0),
        f_choice in (0u8..4, 0usize..64, prop_oneof![Just(1e3), 1e2f64..3e5]),
    ) {
        let segs = segs_of(&bins);
        let h = h_of(&segs, h_choice);
        let f_p = f_p_of(&segs, h, f_choice);
        check(&segs, h, f_p, 32)?;
    }
}
