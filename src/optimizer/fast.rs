//! Fast replanning for a gaze stream (up to 200 Hz).
//!
//! On `N` equal bins with no static priors, the problem is invariant under
//! rotation by whole bins: the limits do not depend on azimuth and the
//! weights depend only on the eccentricity from the gaze. A gaze `g` is
//! split into whole bins `k` and a phase within a bin, quantized to
//! 1/[`PHASE_STEPS`] of a bin (0.016° for 360 bins, far below eye-tracker
//! accuracy). The solution for the phase is solved once and cached; every
//! later gaze with the same phase is that solution rotated by `k` bins, then
//! **certified again** (the checker never trusts the cache). With priors the
//! symmetry is broken and the cache is keyed by the quantized gaze itself.
//!
//! The rotated solution equals a fresh solve at the quantized gaze because
//! the rotated problem is the same LP with its variables renumbered (tests
//! check the profiles agree).

use std::collections::BTreeMap;

use super::{optimize, optimize_unrated, OptError, Problem};
use crate::checker::{certify, CertifiedProfile};
use crate::model::angle::{rotate_index, wrap_deg, FULL_TURN_DEG};
use crate::profile::Profile;

/// Gaze phases per bin ([`super::OptimizerSettings::phase_steps`]).
pub const PHASE_STEPS: u32 = super::OptimizerSettings::DEFAULT.phase_steps;

/// A planner with a solution cache.
#[derive(Debug, Clone)]
pub struct FastPlanner {
    problem: Problem,
    cache: BTreeMap<u64, Profile>,
    rotation_invariant: bool,
    fresh_solves: u64,
}

impl FastPlanner {
    /// A planner for `problem`.
    #[must_use]
    pub fn new(problem: Problem) -> Self {
        let rotation_invariant = problem.objective.priors.is_empty();
        Self {
            problem,
            cache: BTreeMap::new(),
            rotation_invariant,
            fresh_solves: 0,
        }
    }

    /// How many fresh HiGHS solves so far.
    #[must_use]
    pub fn fresh_solves(&self) -> u64 {
        self.fresh_solves
    }

    /// The problem.
    #[must_use]
    pub fn problem(&self) -> &Problem {
        &self.problem
    }

    /// The gaze actually planned for (quantized), degrees.
    #[must_use]
    pub fn quantized_gaze(&self, gaze_deg: f64) -> f64 {
        quantized_gaze(self.problem.bins, gaze_deg)
    }

    /// A certified profile for `gaze_deg`.
    pub fn plan(&mut self, gaze_deg: f64) -> Result<CertifiedProfile, OptError> {
        crate::planner::validate_gaze(gaze_deg).map_err(|e| OptError::Invalid {
            field: "gaze-deg".into(),
            reason: e.to_string(),
        })?;
        let (k, q) = split(self.problem.bins, gaze_deg);
        let width = FULL_TURN_DEG / self.problem.bins as f64;
        if !self.rotation_invariant {
            let key = (k as u64) << 32 | u64::from(q);
            let gaze = self.quantized_gaze(gaze_deg);
            if let Some(p) = self.cache.get(&key) {
                return Ok(certify(p.clone())?);
            }
            let c = optimize(&self.problem, gaze)?;
            self.fresh_solves += 1;
            self.cache.insert(key, c.profile().clone());
            return Ok(c);
        }
        let canonical = match self.cache.get(&u64::from(q)) {
            Some(p) => p,
            None => {
                let c =
                    optimize_unrated(&self.problem, f64::from(q) * width / f64::from(PHASE_STEPS))?;
                self.fresh_solves += 1;
                self.cache
                    .entry(u64::from(q))
                    .or_insert_with(|| c.into_inner())
            }
        };
        let gaze = quantized_gaze(self.problem.bins, gaze_deg);
        let rotated = rotate(canonical, k, gaze);
        match certify(rotated) {
            Ok(c) => Ok(c),
            // A rotated answer at the limit (hardware levels keep no
            // head-room) whose bound rounds the other way: a fresh solve.
            Err(_) => {
                self.fresh_solves += 1;
                optimize(&self.problem, gaze)
            }
        }
    }
}

/// Whole bins `k` and phase step `q` of a gaze on `n` equal bins.
fn split(n: usize, gaze_deg: f64) -> (usize, u32) {
    let width = FULL_TURN_DEG / n as f64;
    let g = wrap_deg(gaze_deg);
    let mut k = (g / width).floor() as usize;
    let mut q = ((g - k as f64 * width) / width * f64::from(PHASE_STEPS)).round() as u32;
    if q >= PHASE_STEPS {
        q = 0;
        k += 1;
    }
    (k % n, q)
}

/// The gaze a quantized plan is for: `k` whole bins plus `q` phase steps.
fn quantized_gaze(n: usize, gaze_deg: f64) -> f64 {
    let (k, q) = split(n, gaze_deg);
    let width = FULL_TURN_DEG / n as f64;
    wrap_deg(k as f64 * width + f64::from(q) * width / f64::from(PHASE_STEPS))
}

/// Rotates a uniform-bin profile by `k` bins (counter-clockwise).
#[must_use]
pub fn rotate(p: &Profile, k: usize, gaze_deg: f64) -> Profile {
    let n = p.bins.len();
    let mut bins = p.bins.clone();
    for (i, b) in p.bins.iter().enumerate() {
        let j = rotate_index(i, k, n);
        bins[j] = b.clone();
        bins[j].start_deg = p.bins[j].start_deg;
        bins[j].width_deg = p.bins[j].width_deg;
    }
    Profile {
        bins,
        gaze_deg: Some(gaze_deg),
        summary: None,
        optimality: None,
        ..p.clone()
    }
}

/// The solutions a set of gazes needs, built in parallel, shared read-only
/// across threads (the simulator's `optimized` variant). A
/// rotation-invariant problem (no priors) keeps one canonical solution per
/// phase and rotates it by whole bins; a problem with priors keeps one
/// solution per quantized gaze (no rotation: the priors break the symmetry).
/// Either way each solve is the one [`super::optimize`] makes at that gaze,
/// and the table is the same whatever the number of threads.
#[derive(Debug, Clone)]
pub struct PhaseTable {
    problem: Problem,
    rotation_invariant: bool,
    /// Invariant: phase `q` → canonical profile (certified again after
    /// every rotation). With priors: the quantized gaze's key → its
    /// certified profile.
    canonical: BTreeMap<u64, Profile>,
    per_gaze: BTreeMap<u64, CertifiedProfile>,
}

impl PhaseTable {
    /// Solves every phase (rotation-invariant problem) or every quantized
    /// gaze (a problem with priors) the `gazes` need.
    pub fn build(problem: &Problem, gazes: &[f64]) -> Result<Self, OptError> {
        use rayon::prelude::*;
        for &g in gazes {
            crate::planner::validate_gaze(g).map_err(|e| OptError::Invalid {
                field: "gaze-deg".into(),
                reason: e.to_string(),
            })?;
        }
        let rotation_invariant = problem.objective.priors.is_empty();
        let n = problem.bins;
        let width = FULL_TURN_DEG / n as f64;
        let mut keys: Vec<u64> = gazes
            .iter()
            .map(|&g| table_key(n, g, rotation_invariant))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        let mut table = Self {
            problem: problem.clone(),
            rotation_invariant,
            canonical: BTreeMap::new(),
            per_gaze: BTreeMap::new(),
        };
        if rotation_invariant {
            let solved: Vec<(u64, Profile)> = keys
                .par_iter()
                .map(|&q| {
                    optimize_unrated(problem, q as f64 * width / f64::from(PHASE_STEPS))
                        .map(|c| (q, c.into_inner()))
                })
                .collect::<Result<_, _>>()?;
            table.canonical = solved.into_iter().collect();
        } else {
            let solved: Vec<(u64, CertifiedProfile)> = keys
                .par_iter()
                .map(|&key| optimize_unrated(problem, key_gaze(n, key)).map(|c| (key, c)))
                .collect::<Result<_, _>>()?;
            table.per_gaze = solved.into_iter().collect();
        }
        Ok(table)
    }

    /// How many solves the table holds (distinct phases, or distinct
    /// quantized gazes with priors).
    #[must_use]
    pub fn solves(&self) -> usize {
        self.canonical.len() + self.per_gaze.len()
    }

    /// The certified profile for `gaze_deg` (its phase, or with priors its
    /// quantized gaze, must have been built).
    pub fn plan(&self, gaze_deg: f64) -> Result<CertifiedProfile, OptError> {
        let n = self.problem.bins;
        let key = table_key(n, gaze_deg, self.rotation_invariant);
        let missing = || OptError::Invalid {
            field: "gaze-deg".into(),
            reason: format!("gaze {gaze_deg} was not built into the table"),
        };
        if !self.rotation_invariant {
            return self.per_gaze.get(&key).cloned().ok_or_else(missing);
        }
        let (k, _) = split(n, gaze_deg);
        let canonical = self.canonical.get(&key).ok_or_else(missing)?;
        Ok(certify(rotate(canonical, k, quantized_gaze(n, gaze_deg)))?)
    }
}

/// The table's key of a gaze: its phase step (rotation-invariant problems)
/// or its whole bins and phase step (with priors).
fn table_key(n: usize, gaze_deg: f64, rotation_invariant: bool) -> u64 {
    let (k, q) = split(n, gaze_deg);
    if rotation_invariant {
        u64::from(q)
    } else {
        (k as u64) << 32 | u64::from(q)
    }
}

/// The quantized gaze of a with-priors key.
fn key_gaze(n: usize, key: u64) -> f64 {
    let width = FULL_TURN_DEG / n as f64;
    let k = (key >> 32) as f64;
    let q = (key & 0xffff_ffff) as f64;
    wrap_deg(k * width + q * width / f64::from(PHASE_STEPS))
}
