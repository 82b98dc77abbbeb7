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

/// Kills `cells.rs` `Cells::sweep`, the curved cells' midpoint sample of the
/// right edge's envelope piece: `t(mid + h) + delta` → `t(mid + h) * delta`
/// in `pr_mid = env.power_at(..)` (reads `P̄` near time 0 instead of the
/// piece under the right edge inside the cell). This generator's case (shrunk by
/// proptest from a failure of the mutant): cell 78 is curved and its right
/// edge's inside piece is hotter than both end samples; with the mutant
/// its `e_ub` (1.34106e-3 J) is below the exact figure of the cell
/// (1.34702e-3 J, from its stationary point), so the pruned search could
/// skip the cell holding the largest pass energy. Fixed here so the kill
/// does not depend on the random stream.
#[test]
fn curved_cell_samples_the_right_edge_piece_at_its_midpoint() {
    let bins: Vec<BinSpec> = vec![
        (0.001, 0.003_383_423_190_297_945, 0.005),
        (
            0.232_528_118_409_558_25,
            0.001_359_857_751_943_493_7,
            0.048_548_613_744_048_16,
        ),
        (0.421_150_955_864_305_5, 0.005, 1.0),
        (0.478_450_448_636_732_7, 0.0, 2.0),
        (0.001, 0.0, 2.0),
        (0.001, 0.0, 2.0),
        (0.985_773_668_528_486_2, 0.002_726_025_142_229_411, 0.001),
        (0.2, 0.0, 0.005),
        (0.324_776_198_787_378_35, 0.0, 2.0),
        (0.871_014_079_579_420_2, 0.0, 2.0),
        (0.006_621_891_946_327_492_5, 0.0, 2.0),
        (0.814_538_886_337_845_9, 0.0, 2.0),
        (0.002_746_435_399_943_662_6, 0.0, 2.0),
        (0.400_801_769_601_810_2, 0.0, 2.0),
        (0.006_998_717_675_824_66, 0.0, 2.0),
        (0.219_892_553_431_059_85, 0.0, 2.0),
        (0.596_349_073_139_978_1, 0.0, 2.0),
        (0.994_594_853_615_787_3, 0.0, 2.0),
        (0.906_022_579_065_936_4, 0.003_168_696_947_349_295_3, 0.005),
        (0.007_180_317_659_860_826, 0.0, 0.790_780_945_237_944_3),
    ];
    let segs = segs_of(&bins);
    let h = h_of(&segs, (0, 0, 2.629_386_609_927_519_4));
    let f_p = f_p_of(&segs, h, (2, 58, 1000.0));
    check(&segs, h, f_p, 32).unwrap();
}
