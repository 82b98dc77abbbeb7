//! Rule 2 over the windows that hold one whole pass (the boundary of the
//! walks' reach): `min(E(φ), E⁺)/AEL_inf(τ(φ))` per cell, and its pruned
//! maximum over the cells (`specs/eye_safety.md`, "Whole-pass windows").

use super::cells::Cells;
use super::count::PRUNE_SLACK;
use super::search::Best;
use super::Search;

impl Cells<'_> {
    /// Rule 2 over the windows that hold one whole pass (the boundary of
    /// the walks' reach, see [`Walks::search`]): an upper bound of
    /// `min(E(φ), E⁺)/AEL_inf(τ(φ))` over the azimuths `φ` of cell `c`, with the
    /// `τ` where it is taken. Off the curved cells `E` and `τ` are affine in
    /// `φ` (both pass edges in bins of constant spin, the envelope pieces
    /// fixed), so on each row of Table 3 `E/AEL(τ) = (e₀ + e₁x)/(c·(τ₀ +
    /// t₁x)^p)` has a derivative whose sign is that of
    /// `e₁τ − p·t₁·E`, affine in `x` with slope `(1 − p)·e₁·t₁`: positive
    /// throughout when `e₁·t₁ < 0` (or its mirror), and crossing zero at
    /// most once upwards otherwise, so the ratio is largest at the cell ends
    /// or where `τ` meets a row edge (with the smaller row there); capped at
    /// `E⁺`, also where `E` reaches `E⁺` (on each side of it the capped
    /// ratio is one of the two forms above). On a curved cell: the largest
    /// `E` (capped) over the smallest AEL between its smallest and largest
    /// `τ` (all exact, see [`Self::exact`]; the AEL may fall at a row
    /// edge).
    ///
    /// The AEL is the smallest over every length of a window holding the
    /// pass and no other, `AEL_inf(τ) = min AEL over [τ, one_pass_s]`
    /// ([`Laser::ael_inf_j`]): `E/AEL_inf(τ) = max(E/AEL(τ), E/m)` with `m`
    /// the later edges' (and `one_pass_s`'s) smallest value, constant
    /// between the points where `τ` meets a row edge, so `E/m` (`E` affine)
    /// is largest at the same candidates, where `AEL_inf` is at most `m`.
    fn full_pass(&self, c: usize, e_cap: f64, one_pass_s: f64) -> (f64, f64) {
        let laser = self.laser;
        // `τ` is a difference of times from 0°: the AEL of a pass
        // `t_pad` shorter (`count::time_rounding_s`).
        let pad = self.t_pad;
        if self.rows[c].curved {
            let x = self.exact(c);
            let r =
                x.e_env.min(e_cap) / laser.ael_inf_j(x.tau_min_s - pad, x.tau_s.max(one_pass_s));
            return (r, x.tau_min_s);
        }
        let (tu, tv) = (self.tau_pt[c], self.tau_pt[c + 1]);
        let (eu, ev) = (self.e_pt[c], self.e_pt[c + 1]);
        let mut best = Best(0.0, 0.0);
        let mut take =
            |e: f64, t: f64| best.take((e.min(e_cap) / laser.ael_inf_j(t - pad, one_pass_s), t));
        take(eu, tu);
        take(ev, tv);
        // Along the cell `E` is affine in `τ`. Interpolations are widened by
        // the error of the values at the cuts (`PRUNE_SLACK` of a turn's
        // time and envelope energy) amplified by the division.
        let t_err = 2.0 * PRUNE_SLACK * self.tl.period_s();
        let e_err = 2.0 * PRUNE_SLACK * self.env.total_j();
        let (lo, hi) = (tu.min(tv), tu.max(tv));
        let (de, dt) = (ev - eu, tv - tu);
        for t in laser.edges_within(lo, hi) {
            let w = ((t - tu) / dt).clamp(0.0, 1.0);
            let spread = (t_err / (hi - lo)).min(1.0);
            let e = eu + de * w + de.abs() * spread + e_err;
            // (Affine: never above the larger end.)
            take(e.min(eu.max(ev)), t);
        }
        // Where `E` reaches `E⁺` (the cap's kink): `E⁺` over the `τ` there.
        if eu.min(ev) < e_cap && e_cap < eu.max(ev) {
            let w = ((e_cap - eu) / de).clamp(0.0, 1.0);
            let spread = (e_err / de.abs()).min(1.0);
            let t = tu + dt * w - dt.abs() * spread - t_err;
            // (Affine: never below the smaller end.)
            take(e_cap, t.max(lo));
        }
        (best.0, best.1)
    }

    /// The largest [`Self::full_pass`] over the cells and `best`. Pruned: a cell is
    /// evaluated only if `min(E_ub, E⁺)/τ_lb · K` ([`Laser::mean_power_factor`]
    /// up to the longest pass), then `min(E_ub, E⁺)` over the smallest AEL
    /// between `τ_lb` and `max(τ_ub, one_pass_s)`, both upper bounds of its value, can reach
    /// the best so far.
    pub(super) fn full_pass_max(
        &self,
        search: Search,
        e_cap: f64,
        tau_max: f64,
        one_pass_s: f64,
        mut best: Best,
    ) -> Best {
        match search {
            Search::Exhaustive => {
                for c in 0..self.len() {
                    best.take(self.full_pass(c, e_cap, one_pass_s));
                }
            }
            Search::Pruned => {
                let laser = self.laser;
                // `τ/AEL_inf(τ − pad) ≤ K + pad/AEL_min` (the shift of
                // `full_pass`), `AEL_min` the table's smallest.
                let pad = self.t_pad;
                let k = (laser.mean_power_factor(tau_max, one_pass_s)
                    + pad / laser.ael_inf_j(0.0, crate::eye_safety::ael::T_MAX_TABLE_S))
                    * (1.0 + PRUNE_SLACK);
                for (c, row) in self.rows.iter().enumerate() {
                    // (A NaN bound never prunes; a bound `τ_lb ≤ 0` only
                    // through the AEL, which clamps it.)
                    let e = row.env_ub.min(e_cap);
                    if row.tau_lb > 0.0 && e / row.tau_lb * k < best.0 {
                        continue;
                    }
                    let ael = laser.ael_inf_j(row.tau_lb - pad, row.tau_ub.max(one_pass_s));
                    if e / ael * (1.0 + PRUNE_SLACK) < best.0 {
                        continue;
                    }
                    best.take(self.full_pass(c, e_cap, one_pass_s));
                }
            }
        }
        best
    }
}
