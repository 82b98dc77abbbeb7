//! The global bound under `objective.kind = "detection"`: on small
//! instances of every shipped config, the optimizer's answer and thousands
//! of feasible perturbations of it (power traded between two bins at equal
//! spend; without an acceleration limit, dwell traded too) never exceed
//! `upper_bound`, and the answer's figures carry it.

use super::perturb::{never_above_the_bound, Moves};
use gaze_lidar::optimizer::global::{model_objective, upper_bound};
use gaze_lidar::optimizer::{optimize, ObjectiveKind, OptimizerConfig};
use rand::SeedableRng;

const CONFIGS: [&str; 4] = ["paper", "multi_level", "smooth", "vls128_eye"];

#[test]
fn the_detection_bound_is_never_exceeded_on_small_instances() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(30);
    for name in CONFIGS {
        let text = std::fs::read_to_string(format!("examples/configs/{name}.toml")).unwrap();
        let mut problem = OptimizerConfig::from_toml(&text, name)
            .unwrap()
            .problem()
            .unwrap();
        problem.bins = 12;
        problem.objective.kind = ObjectiveKind::Detection;
        let gaze = 90.0;
        let answer = optimize(&problem, gaze).unwrap().profile().clone();
        let ub = upper_bound(&problem, gaze).unwrap();
        let j0 = model_objective(&problem, gaze, &answer).unwrap();
        assert!(j0 <= ub, "{name}: answer {j0} above the bound {ub}");
        let global = answer
            .optimality
            .as_ref()
            .and_then(|o| o.global.as_ref())
            .expect("optimality.global under detection");
        assert!(global.upper_bound == ub && global.objective <= j0);
        let moves = Moves {
            level_jumps: true,
            spins_in_setpoint_hull: true,
            draws: 3000,
        };
        let (tried, best) =
            never_above_the_bound(name, &problem, gaze, &answer, (j0, ub), moves, &mut rng);
        eprintln!(
            "{name} (12 bins, detection): answer {j0}, best of {tried} feasible perturbations {best}, bound {ub} (relative gap {:.2e})",
            (ub - j0) / ub
        );
        assert!(tried > 50, "{name}: only {tried} feasible perturbations");
    }
}
