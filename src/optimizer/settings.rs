//! Every tuning constant of the optimizer in one table, each with its
//! default and the reason for it (in the manner of Clarabel's
//! `DefaultSettings`). The programs, the loop and the global bound read
//! [`OptimizerSettings::DEFAULT`]; nothing else in `src/optimizer` holds a
//! tuning number. (Fixed-width arithmetic sizes in `exact` and the fill's
//! rounding bound in `utility` are derived quantities, not tuning.)

/// The optimizer's tuning constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimizerSettings {
    // --- The programs' shape -------------------------------------------
    /// Chords of the piecewise-linear utilities (default 16).
    pub utility_segments: usize,
    /// Chords of the density utility on a dwell column inside a trust
    /// region (default 4): a sequential LP's first-order model, where the
    /// acceleration rows allow far smaller moves still. Measured on
    /// `smooth` (360 bins, joint): 16 chords → 4 makes the whole solve 1.8×
    /// faster (99 → 55 ms) and moves the answer's exact objective by 2e-14
    /// relative (`optimality.global.objective` 8.864885452179 either way).
    /// Columns without a trust region keep `utility_segments`.
    pub trust_region_segments: usize,
    /// Widest `√`-span of a utility's box spread evenly over its chords
    /// (default 2, a box from 0 to 4 times the mean). A wider box (a
    /// `power_w_max` far above the budget) keeps `utility_segments −
    /// utility_tail_segments` chords evenly on the first 2 of `√` and the
    /// rest geometric in `√` up to the box's end: evenly over a box to
    /// 12,500 × the mean, the first chord alone ran to 48.8 × (linear
    /// there), and the power step put a 36-bin budget into one bin, 5 ×
    /// below the uniform profile's objective. Every shipped config's boxes
    /// are narrower (chords unchanged).
    pub utility_dense_sqrt_span: f64,
    /// Chords of a wide box's geometric tail (default 4).
    pub utility_tail_segments: usize,
    /// Tie-break added to the weights, growing with signed eccentricity
    /// (default 1e-3): makes the optimum unique where the acuity is
    /// symmetric about the gaze, and is itself rotation-equivariant (a
    /// function of eccentricity only), so a rotated problem has the rotated
    /// optimum.
    pub tie_break: f64,
    /// Most bins the optimizer accepts (default 1,440: 0.25° bins). The
    /// profile format and the closed forms go to `model::angle::MAX_BINS`
    /// (36,000), but the LP grows with the bin count and with the
    /// eye-safety windows aligned with every bin edge, and its solve time
    /// grows faster than linearly: measured on a shared 2-core machine,
    /// 1,440 bins ≈ 4.5 s of CPU, 3,600 bins ≈ 22 s, 36,000 bins did not
    /// finish in 20 s. 1,440 keeps a solve in seconds.
    pub max_bins: usize,

    // --- Margins (rounding towards safety) ------------------------------
    /// Relative margin kept from continuous bounds, budget and caps
    /// (default 1e-6): continuous solutions are clamped and rescaled to
    /// meet bounds, budget and frame exactly.
    pub margin: f64,
    /// Relative slack on the budget row of a level (MILP) power step
    /// (default 2e-10): HiGHS accepts a MILP's rows to
    /// `mip_feasibility_tol` (1e-10, absolute, on a row of order one to 2π)
    /// and a level choice has no continuous part to trim, so the certified
    /// row allows 2e-10 relative; 5× inside the checker's `REL_TOL` (1e-9).
    pub level_budget_slack: f64,
    /// Relative margin every eye-safety cut keeps below its limit (default
    /// 2e-7): HiGHS's feasibility tolerance (1e-7 on rows normalised to 1)
    /// beyond the head-room and the bound's own rounding margin
    /// (`RATIO_MARGIN`).
    pub cut_margin: f64,
    /// Head-room the power step leaves under the Class 1 limit of the bound
    /// (default 1e-9), so that a rotated copy of its answer (the fast path)
    /// still certifies.
    pub eye_safety_headroom: f64,

    // --- The loop -------------------------------------------------------
    /// Rounds of the cutting-plane loop of one power step (default 60).
    pub cut_rounds: usize,
    /// Window cuts a round of the first half of that loop adds at most,
    /// the ones the answer breaks most (default 256): HiGHS re-solves the
    /// last round's model from its basis, and a few hundred rows at a time
    /// keep each re-solve short. Measured on the `vls128` head at a budget
    /// its eye safety binds (720 bins): every cut at once, 8,663 rows in
    /// the second program, 6.4 s of CPU; 256 a round, 4.0 s; 50 and 100 a
    /// round took more rounds for no less time (5.3 and 4.0 s).
    pub cuts_per_round: usize,
    /// Cuts at or above this ratio of the current iterate are binding: the
    /// dwell step linearises them (default 1 − 1e-3).
    pub binding: f64,
    /// Trust region of the sequential LP for acceleration limits (default 0.3).
    pub trust: f64,
    /// Share of the acceleration limit the linearised constraint may use
    /// (default 0.8).
    pub accel_share: f64,
    /// Dwell-step iterations when the acceleration limit is finite (at
    /// most; default 5).
    pub slp_rounds: usize,
    /// Priced block-coordinate rounds under time accounting without an
    /// acceleration limit, at most (default 30; `lp::priced_rounds`).
    pub priced_rounds: usize,
    /// Relative rise of the model objective a priced round must bring to
    /// be kept (default 1e-9; the first that brings less ends them).
    pub priced_gain: f64,
    /// The sequential LP stops once a dwell step moves no bin's dwell by
    /// more than this (relative; default 1e-3). On `smooth` (360 bins,
    /// joint) the five rounds' moves were 2.7e-2, 7.6e-4, 2.4e-5, 3.2e-6,
    /// 3.7e-6; stopping after the second changes the answer's exact
    /// objective by −1.4e-7 relative (8.864885070 with five rounds,
    /// 8.864884199 with two; the global gap is 2.4e-2) and makes the whole
    /// process 1.24× faster than stopping after the third (1e-4).
    pub slp_settled: f64,
    /// Shrink steps tried (towards the power floor) when rounding leaves a
    /// row of the power step's certificate a few ulps over (default 40).
    pub repair_tries: usize,

    // --- HiGHS ------------------------------------------------------------
    /// HiGHS's `primal_feasibility_tolerance` on the power steps and the
    /// global relaxation (default 1e-7: HiGHS's own default).
    pub primal_feasibility_tol: f64,
    /// HiGHS's primal feasibility tolerance on the dwell step's program
    /// (default 1e-9): the certified program's rows are widened by
    /// `2·dwell_feasibility_tol·(1 + Σ|a|)` (`LinearProgram::widened`).
    pub dwell_feasibility_tol: f64,
    /// Branch-and-bound nodes a MILP may use before its best incumbent is
    /// taken (default 100). Multiple-choice knapsacks with unequal weights
    /// (hardware power levels under time accounting once the dwell moves,
    /// `joint` mode) take HiGHS minutes to close to a zero gap at 90 bins
    /// (measured: 66–82 s) for an answer the certificate cannot tell apart:
    /// its bound comes from the LP relaxation's duals, not from the search.
    /// A node count, unlike a time limit, keeps answers deterministic; the
    /// exact gap is reported.
    pub mip_max_nodes: i32,
    /// A MILP's branch and bound is skipped when the primal heuristic's
    /// point (hardware power levels: `level_choice`) is within this
    /// relative distance of the LP relaxation's optimum (default 1e-3, a
    /// tenth of the 1 % the power step's gap may be): the relaxation bounds
    /// the MILP, so the search could gain no more, and the certificate's
    /// bound comes from the relaxation's duals either way. Measured on the
    /// random family (seed 30): HiGHS's 100 nodes at 360–720 bins took
    /// 2.5–6.5 s of CPU per power step and ended 1.3·10⁻⁵–2.2·10⁻⁴ below
    /// the relaxation; the heuristic, in milliseconds, 2.8·10⁻⁵–2.2·10⁻⁴.
    pub mip_heuristic_gap: f64,
    /// The search's second limit when the first ended without a feasible
    /// point (default 5,000; an equality knapsack: spin set-points meeting
    /// the frame period); without one there either, the step reports that
    /// it found none.
    pub mip_max_nodes_without_incumbent: i32,
    /// Steps of the search for a choice of spin set-points that meets the
    /// frame period on equal bins before any solve (default 5·10⁷; one step
    /// per count of all set-points but the last two: about `C(N+K−2, K−2)`
    /// for `K` set-points on `N` bins, 2.6·10⁵ at 720 bins and 4
    /// set-points, 6.3·10⁷ with 5, past the default); past it the dwell
    /// step decides.
    pub setpoint_search_steps: u64,
    /// With spin set-points, the dwell step's `frame` row is the band
    /// `N·(1 ± setpoint_frame_tol)` (default 0.99·10⁻⁹, inside the
    /// checker's relative 10⁻⁹ on the frame period by far more than the
    /// float sums' 10⁻¹³): set-points read from a datasheet meet the frame
    /// period only to the checker's tolerance, never to HiGHS's absolute
    /// 10⁻¹⁰ of an equality.
    pub setpoint_frame_tol: f64,
    /// Steps of the set-point heuristic's search for a composition near the
    /// relaxation's counts that meets the `frame` band (default 2·10⁷,
    /// about 0.3 s; one step per count of all set-points but the last
    /// two).
    pub setpoint_heuristic_steps: u64,
    /// The set-point heuristic's point is taken without a branch and bound
    /// within this relative distance of the relaxation's optimum (default
    /// 5·10⁻², stated in the certificate). Set-points meet the frame band
    /// only in rare compositions (measured: six set-points on 360 bins,
    /// none within 16 bins of the relaxation's counts), so the relaxation
    /// is out of reach by a few 10⁻³ to 10⁻², and HiGHS's search on such
    /// an equality knapsack took over 14 s of CPU without a point; from
    /// the heuristic's point (five and six set-points evenly 60.123–300.123
    /// rad/s, 360 and 720 bins, relative gaps 1.6–3.0 %) its 100 nodes
    /// took 1.5 s of CPU and returned the heuristic's objective each time.
    pub setpoint_heuristic_gap: f64,
    /// At most this many swaps of two bins' set-points when a
    /// `resolution`-mode set-point answer is over the eye-safety limit
    /// (default 360; each costs one evaluation of the bound).
    pub setpoint_spread_swaps: usize,
    /// The neighbourhood of the worst azimuth whose slowest bin a swap
    /// moves, and the size of the neighbourhoods compared, degrees either
    /// side (default 5°: the bound's windows span a few degrees; a
    /// heuristic's choice only, the bound decides every answer).
    pub setpoint_spread_window_deg: f64,
    /// HiGHS's `mip_feasibility_tolerance` for every MILP (default 1e-10,
    /// its minimum): its default, 1e-6, lets a level choice overspend the
    /// budget by far more than the checker's relative 1e-9.
    pub mip_feasibility_tol: f64,
    /// A program whose every cost is below this in magnitude (default
    /// 2⁻¹⁰) goes to HiGHS with its objective multiplied by the power of
    /// two that brings the largest cost into `[1, 2)` (HiGHS's dual
    /// tolerance is an absolute 1e-7: small weights, which are relative,
    /// would otherwise stop it early); its answers are divided back.
    pub objective_scale_below: f64,
    /// Distance from an integer within which a relaxation's value counts as
    /// integral (default 1e-9; HiGHS's own `mip_feasibility_tolerance` is
    /// 1e-6).
    pub relaxation_integrality_tol: f64,

    // --- The global bound -------------------------------------------------
    /// Tangents per utility and bin in the global relaxation (default 12).
    pub global_tangents: usize,
    /// The checker's relative tolerance, by which every row of the global
    /// relaxation is widened (default 1e-9).
    pub global_widen: f64,
    /// τ slices per bin in the coupled Lagrangian's final evaluation
    /// (default 256).
    pub lagrangian_slices: usize,
    /// Relative lowering of the floating-point objective, and raising of
    /// the bound (rounding cover; default 1e-12).
    pub objective_margin: f64,
    /// Pieces of the coarse slicing the multipliers' golden-section search
    /// uses (default 16), and its rounds (default 1). Measured on `smooth`
    /// (bound 8.91687 at the LP's multipliers): one round 8.91094 in 4 ms,
    /// three 8.91085 in 15 ms.
    pub multiplier_pieces: usize,
    /// See `multiplier_pieces`.
    pub multiplier_rounds: usize,

    // --- The fast path ----------------------------------------------------
    /// Gaze phases per bin of the fast path's canonical solutions (default
    /// 64: 1/64 of a bin, 0.016° for 360 bins, far below eye-tracker
    /// noise).
    pub phase_steps: u32,
}

impl OptimizerSettings {
    /// The defaults (each field's documentation gives its reason).
    pub const DEFAULT: Self = Self {
        utility_segments: 16,
        trust_region_segments: 4,
        utility_dense_sqrt_span: 2.0,
        utility_tail_segments: 4,
        tie_break: 1e-3,
        max_bins: 1440,
        margin: 1e-6,
        level_budget_slack: 2e-10,
        cut_margin: 2e-7,
        eye_safety_headroom: 1e-9,
        cut_rounds: 60,
        cuts_per_round: 256,
        binding: 1.0 - 1e-3,
        trust: 0.3,
        accel_share: 0.8,
        slp_rounds: 5,
        priced_rounds: 30,
        priced_gain: 1e-9,
        slp_settled: 1e-3,
        repair_tries: 40,
        primal_feasibility_tol: 1e-7,
        dwell_feasibility_tol: 1e-9,
        setpoint_search_steps: 50_000_000,
        setpoint_frame_tol: 0.99e-9,
        setpoint_heuristic_steps: 20_000_000,
        setpoint_heuristic_gap: 5e-2,
        setpoint_spread_swaps: 360,
        setpoint_spread_window_deg: 5.0,
        mip_max_nodes: 100,
        mip_heuristic_gap: 1e-3,
        mip_max_nodes_without_incumbent: 5000,
        mip_feasibility_tol: 1e-10,
        objective_scale_below: 1.0 / 1024.0,
        relaxation_integrality_tol: 1e-9,
        global_tangents: 12,
        global_widen: 1e-9,
        lagrangian_slices: 256,
        objective_margin: 1e-12,
        multiplier_pieces: 16,
        multiplier_rounds: 1,
        phase_steps: 64,
    };
}

impl Default for OptimizerSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The table the optimizer runs with.
pub(crate) const S: OptimizerSettings = OptimizerSettings::DEFAULT;

#[cfg(test)]
mod tests {
    use super::*;

    /// The margins keep their order: the level slack inside the checker's
    /// relative tolerance (1e-9), the cut margin above HiGHS's feasibility
    /// tolerance, the dwell tolerance covering HiGHS's integrality one.
    #[test]
    fn margins_keep_their_reasons() {
        let s = OptimizerSettings::default();
        assert!(s.level_budget_slack * 5.0 <= 1e-9 * (1.0 + 1e-12));
        assert!(s.cut_margin > s.primal_feasibility_tol);
        assert!(s.mip_feasibility_tol <= s.dwell_feasibility_tol);
        assert!(s.trust > 0.0 && s.trust < 1.0 && s.accel_share <= 1.0);
        assert!(s.binding < 1.0 && s.eye_safety_headroom < s.cut_margin);
    }
}
