//! When the LiDAR fires and where it points: CARLA's fixed-tick sampling,
//! its asynchronous variant, or the project's free-running pulse clock.
//!
//! **CARLA** (`LibCarla`/`Unreal/CarlaUE4/Plugins/Carla/Source/Carla/Sensor/
//! RayCastSemanticLidar.cpp`, `ARayCastSemanticLidar::SimulateLidar`, which
//! `ARayCastLidar` inherits; read at commit 001f560e), once per simulation
//! tick of length `DeltaTime`:
//!
//! 1. `PointsToScanWithOneLaser = RoundHalfFromZero(PointsPerSecond ·
//!    DeltaTime / Channels)` (float arithmetic) — [`points_per_laser`];
//! 2. `AngleDistanceOfTick = RotationFrequency · HorizontalFov · DeltaTime`,
//!    `AngleDistanceOfLaserMeasure = AngleDistanceOfTick /
//!    PointsToScanWithOneLaser`;
//! 3. point `i` of every laser at `HorizAngle = fmod(CurrentHorizontalAngle
//!    + AngleDistanceOfLaserMeasure · i, HorizontalFov) − HorizontalFov/2`;
//! 4. all of them traced against the world as it is after the tick's
//!    physics step (`PostPhysTick`), sent together (one callback);
//! 5. the start angle advances by the whole tick:
//!    `fmod(CurrentHorizontalAngle + AngleDistanceOfTick, HorizontalFov)`;
//!    it is 0 when the sensor is spawned (`FSemanticLidarData`).
//!
//! At the paper's fixed 0.05 s tick, 20 Hz and 500,000 points/s over 64
//! channels that is 391 points per laser per tick (390.625 rounded) over
//! exactly 360°: every tick repeats the same azimuths, 360°/391 apart.
//!
//! Here a scan angle is a fraction of the profile's turn, and a profile's
//! azimuth at a fraction `u` is its timeline's azimuth at `u · period`: for a
//! uniform spin (all of the paper code's variants) that is CARLA's angle
//! `u · 360°` from the profile's start. CARLA has one rotation frequency;
//! an adaptive spin (the closed-form resolution control, eq. 5–6) is not
//! something stock CARLA can run. Under CARLA sampling it means a sensor with
//! CARLA's tick semantics whose points are spread evenly *in time* over the
//! tick and placed by the profile's timeline (slow where it dwells) —
//! CARLA's own rule when the spin is uniform. The profile's power is looked
//! up by azimuth either way, as ARGUS scales intensity by azimuth. The
//! rotation frequency is the profile's `frame_rate_hz`; `PointsPerSecond`
//! is its `pulse_rate_hz` times the channels.
//!
//! Two conventions differ from CARLA and change nothing measured: CARLA's
//! yaw turns clockwise seen from above and ARGUS mounts the sensor at
//! yaw 180° (`lidar2.py`, `lidar_setup`), so its points run clockwise from
//! the ego's forward axis, while here they run the profile's way
//! (counter-clockwise) from its start; the scene is frozen over the tick, so
//! within a tick only the order of points differs (the 1-in-5.4 decimation
//! of the resolution variant takes them in that order). CARLA computes in
//! `float`; here the angle is kept in `f64` turn fractions (CARLA's point
//! count is computed in `f32`, as it does).
//!
//! The sensor's start angle at the trial's first tick: CARLA's angle at
//! spawn is 0, and a whole number `m` of ticks has passed since then (ARGUS
//! spawns the sensor before the run; how many ticks before is not in the
//! code): `frac(m · f · dt)` turns, `m` drawn per trial. At 20 Hz and
//! 0.05 s every `m` gives 0: all trials see the same azimuths. The
//! scenario's `carla.grid_phase_steps` (assumed 0) shifts that start by a
//! fraction of one azimuth step of the nominal tick's grid, the sensitivity
//! sweep's "grid phase".
//!
//! **Asynchronous CARLA** (ARGUS never sets `synchronous_mode` or
//! `fixed_delta_seconds`): the same rules with each tick's `DeltaTime`
//! drawn uniformly from `tick_s · [1 − j, 1 + j]`, `j` the scenario's
//! `carla.async_tick_jitter_frac` — an assumption (0.2 by default): the
//! spread of the server's frame times on the paper's machine is not known.
//!
//! **Drift** (the project's pulse clock): pulse `k` fires at `k /
//! pulse_rate_hz` at the profile's azimuth for that time plus the trial's
//! random phase; at 7812.5 pulses/s a 0.05 s tick holds 390.625 pulses, so
//! the azimuths drift by 0.625 of a step per tick.

use super::super::trial::mix64;

/// How the LiDAR is sampled in the `carla` geometry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sampling {
    /// CARLA's fixed tick: `round(rate · dt)` points per laser per tick,
    /// evenly over the tick's rotation, the start angle advancing by it.
    #[default]
    Carla,
    /// CARLA in asynchronous mode: the same per tick, with each tick's
    /// length jittered (`carla.async_tick_jitter_frac`, assumed).
    CarlaAsync,
    /// The free-running pulse clock `k / pulse_rate_hz` (the planar
    /// geometry's, and the `carla` geometry's before sampling existed).
    Drift,
}

crate::names::named_enum!(Sampling {
    Carla => "carla", "CARLA's fixed tick: `round(rate · dt)` points per laser per tick, evenly over the tick's rotation, the start angle advancing by it";
    CarlaAsync => "carla-async", "CARLA in asynchronous mode: the same per tick, with each tick's length jittered (`carla.async_tick_jitter_frac`, assumed)";
    Drift => "drift", "The free-running pulse clock `k / pulse_rate_hz` (the planar geometry's, and the `carla` geometry's before sampling existed)";
});

/// CARLA's points per laser per tick: `RoundHalfFromZero(PointsPerSecond ·
/// DeltaTime / float(ChannelCount))`, in `float` as CARLA computes it
/// (`PointsPerSecond` an integer attribute, `DeltaTime` a `float`).
#[must_use]
pub fn points_per_laser(points_per_second: u32, delta_time_s: f64, channels: u32) -> u32 {
    // f32::round rounds half away from zero, as FMath::RoundHalfFromZero.
    let x = points_per_second as f32 * delta_time_s as f32 / channels as f32;
    if x.is_finite() && x > 0.0 {
        x.round() as u32
    } else {
        0
    }
}

/// One scheduled pulse (all channels fire together).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scheduled {
    /// Simulation tick.
    pub tick: u64,
    /// The tick's end, s (the world is posed then; detection at the callback).
    pub tick_end_s: f64,
    /// Profile turn (frame) the pulse falls in.
    pub frame: u64,
    /// Time into the profile's turn, s (`0 ≤ tau ≤ period`).
    pub tau_s: f64,
}

/// The inputs of a schedule.
#[derive(Debug, Clone, Copy)]
pub struct ScheduleSpec {
    /// Sampling.
    pub sampling: Sampling,
    /// The profile's pulse rate (per laser), Hz.
    pub pulse_rate_hz: f64,
    /// The profile's rotation frequency, Hz.
    pub frame_rate_hz: f64,
    /// The profile's period (its timeline's), s.
    pub period_s: f64,
    /// Channels.
    pub channels: u32,
    /// Nominal tick, s.
    pub tick_s: f64,
    /// Asynchronous tick jitter: `dt ∈ tick_s·[1 − j, 1 + j]`.
    pub jitter_frac: f64,
    /// The trial's phase draw in `[0, 1)` (drift: the phase; carla: the
    /// ticks since the sensor was spawned).
    pub phase_frac: f64,
    /// Seed of the asynchronous tick lengths.
    pub seed: u64,
    /// CARLA sampling: the scan grid's phase at the first tick, in steps
    /// of the nominal tick's grid (`[0, 1)`; `drift` ignores it).
    pub grid_phase_steps: f64,
    /// Simulate while the pulse time (drift) or tick start (carla) is below this, s.
    pub t_end_s: f64,
}

/// Uniform in `[0, 1)` from a key.
fn unit(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The pulses of a trial and the simulated time, s.
#[must_use]
pub fn schedule(spec: &ScheduleSpec) -> (Vec<Scheduled>, f64) {
    match spec.sampling {
        Sampling::Drift => drift(spec),
        Sampling::Carla | Sampling::CarlaAsync => carla(spec),
    }
}

/// The project's pulse clock (exactly the loop it replaces).
fn drift(spec: &ScheduleSpec) -> (Vec<Scheduled>, f64) {
    let rate = spec.pulse_rate_hz;
    let period = spec.period_s;
    let phase = spec.phase_frac * period;
    let n = (spec.t_end_s * rate).floor() as u64;
    let out = (0..n)
        .map(|k| {
            let t = k as f64 / rate;
            let tick = (t / spec.tick_s).floor() as u64;
            let tau_total = t + phase;
            let frame = (tau_total / period).floor() as u64;
            let tau = (tau_total - frame as f64 * period).clamp(0.0, period);
            Scheduled {
                tick,
                tick_end_s: (tick + 1) as f64 * spec.tick_s,
                frame,
                tau_s: tau,
            }
        })
        .collect();
    (out, n as f64 / rate)
}

/// Ticks since spawn at the trial's first tick, from the phase draw.
fn ticks_since_spawn(phase_frac: f64) -> u64 {
    (phase_frac.clamp(0.0, 1.0) * 65_536.0) as u64
}

/// CARLA's tick rule (module docs).
fn carla(spec: &ScheduleSpec) -> (Vec<Scheduled>, f64) {
    let pps = (spec.pulse_rate_hz * f64::from(spec.channels)).round() as u32;
    let dt_of = |n: u64| match spec.sampling {
        Sampling::CarlaAsync => {
            let u = unit(spec.seed ^ n.wrapping_mul(0xA076_1D64_78BD_642F));
            spec.tick_s * (1.0 + spec.jitter_frac * (2.0 * u - 1.0))
        }
        _ => spec.tick_s,
    };
    // Start angle (turns) at the first tick: m whole nominal ticks after
    // spawn at angle 0.
    let adv0 = spec.frame_rate_hz * spec.tick_s;
    let m = ticks_since_spawn(spec.phase_frac);
    let mut u = (m as f64 * adv0).fract();
    if spec.grid_phase_steps != 0.0 {
        let points0 = points_per_laser(pps, spec.tick_s, spec.channels);
        if points0 > 0 {
            u = (u + spec.grid_phase_steps * adv0 / f64::from(points0)).fract();
        }
    }
    let mut frame = 0u64;
    let mut t = 0.0;
    let mut out = Vec::new();
    let mut n = 0u64;
    while t < spec.t_end_s {
        let dt = dt_of(n);
        let points = points_per_laser(pps, dt, spec.channels);
        // AngleDistanceOfTick in turns.
        let adv = spec.frame_rate_hz * dt;
        let step = if points > 0 {
            adv / f64::from(points)
        } else {
            0.0
        };
        let tick_end = match spec.sampling {
            Sampling::CarlaAsync => t + dt,
            _ => (n + 1) as f64 * spec.tick_s,
        };
        for i in 0..points {
            let turn = u + step * f64::from(i);
            let whole = turn.floor();
            out.push(Scheduled {
                tick: n,
                tick_end_s: tick_end,
                frame: frame + whole as u64,
                tau_s: ((turn - whole) * spec.period_s).clamp(0.0, spec.period_s),
            });
        }
        let next = u + adv;
        let whole = next.floor();
        frame += whole as u64;
        u = next - whole;
        t = tick_end;
        n += 1;
    }
    (out, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper(sampling: Sampling) -> ScheduleSpec {
        ScheduleSpec {
            sampling,
            pulse_rate_hz: 7812.5,
            frame_rate_hz: 20.0,
            period_s: 0.05,
            channels: 64,
            tick_s: 0.05,
            jitter_frac: 0.2,
            phase_frac: 0.3,
            seed: 7,
            grid_phase_steps: 0.0,
            t_end_s: 1.0,
        }
    }

    #[test]
    fn grid_phase_shifts_every_carla_azimuth_by_its_fraction_of_a_step() {
        let base = schedule(&paper(Sampling::Carla)).0;
        for g in [0.25, 0.5, 0.999] {
            let shifted = schedule(&ScheduleSpec {
                grid_phase_steps: g,
                ..paper(Sampling::Carla)
            })
            .0;
            assert_eq!(shifted.len(), base.len());
            for (a, b) in base.iter().zip(&shifted) {
                // In degrees: b = a + g · 360/391 (mod 360).
                let d = (b.tau_s - a.tau_s) / 0.05 * 360.0;
                let d = d.rem_euclid(360.0);
                assert!((d - g * 360.0 / 391.0).abs() < 1e-9, "{g}: {d}");
                assert_eq!(a.tick, b.tick);
            }
        }
        // The drift clock has its own per-trial phase and ignores it.
        let drift = paper(Sampling::Drift);
        assert_eq!(
            schedule(&drift),
            schedule(&ScheduleSpec {
                grid_phase_steps: 0.5,
                ..drift
            })
        );
    }

    #[test]
    fn carla_points_per_laser_from_the_source() {
        // 500,000 · 0.05 / 64 = 390.625 → 391 (RoundHalfFromZero).
        assert_eq!(points_per_laser(500_000, 0.05, 64), 391);
        // ARGUS's resolution variant: 687,500 · 0.05 / 64 = 537.1 → 537.
        assert_eq!(points_per_laser(687_500, 0.05, 64), 537);
        // A half rounds away from zero: 100 · 0.05 / 1 = 5 exactly; 30 · 0.05 = 1.5 → 2.
        assert_eq!(points_per_laser(30, 0.05, 1), 2);
        assert_eq!(points_per_laser(10, 0.05, 1), 1);
        // Too few points: none (CARLA logs a warning and skips the tick).
        assert_eq!(points_per_laser(1, 0.05, 64), 0);
        // CARLA's own default: 56,000 points/s, 32 channels, at 0.05 s: 87.5 → 88.
        assert_eq!(points_per_laser(56_000, 0.05, 32), 88);
    }

    #[test]
    fn carla_at_the_papers_tick_repeats_391_azimuths_over_360_degrees() {
        let (pulses, t) = schedule(&paper(Sampling::Carla));
        assert_eq!(pulses.len(), 20 * 391);
        assert_eq!(t, 20.0 * 0.05);
        for tick in 0..20u64 {
            let these: Vec<&Scheduled> = pulses.iter().filter(|p| p.tick == tick).collect();
            assert_eq!(these.len(), 391);
            for (i, p) in these.iter().enumerate() {
                // CARLA: HorizAngle = fmod(0 + (360/391)·i, 360) from the start;
                // here as a fraction of the 0.05 s turn.
                let carla_deg = (360.0 / 391.0) * i as f64;
                assert!(
                    (p.tau_s / 0.05 * 360.0 - carla_deg).abs() < 1e-9,
                    "{tick} {i}"
                );
                // Bit for bit the same as the first tick's.
                assert_eq!(p.tau_s, pulses[i].tau_s);
                assert_eq!(p.frame, tick);
                assert_eq!(p.tick_end_s, (tick + 1) as f64 * 0.05);
            }
        }
    }

    #[test]
    fn carla_at_27_5_hz_advances_495_degrees_per_tick() {
        // ARGUS's resolution variant: 537 points over 27.5 · 360 · 0.05 =
        // 495° per tick; the start angle advances 135° (mod 360) per tick.
        let spec = ScheduleSpec {
            pulse_rate_hz: 687_500.0 / 64.0,
            frame_rate_hz: 27.5,
            period_s: 1.0 / 27.5,
            phase_frac: 0.0,
            ..paper(Sampling::Carla)
        };
        let (pulses, _) = schedule(&spec);
        assert_eq!(pulses.len(), 20 * 537);
        let step_deg = 495.0 / 537.0;
        for (k, p) in pulses.iter().enumerate() {
            let (tick, i) = (k / 537, k % 537);
            let carla_deg = (135.0 * tick as f64 + step_deg * i as f64) % 360.0;
            let ours = p.tau_s * 27.5 * 360.0;
            let d = (ours - carla_deg).abs();
            assert!(d.min(360.0 - d) < 1e-7, "{tick} {i}: {ours} vs {carla_deg}");
            // Turns elapsed: 1.375 per tick.
            let turns = 1.375 * tick as f64 + (495.0 / 360.0) * i as f64 / 537.0;
            assert_eq!(p.frame, turns.floor() as u64, "{tick} {i}");
        }
    }

    #[test]
    fn carla_start_angle_is_a_whole_number_of_ticks_after_spawn() {
        // 20 Hz: every draw gives the same azimuths.
        for phase in [0.0, 0.1, 0.5, 0.999] {
            let a = schedule(&ScheduleSpec {
                phase_frac: phase,
                ..paper(Sampling::Carla)
            });
            assert_eq!(a, schedule(&paper(Sampling::Carla)));
        }
        // 27.5 Hz: the start is one of the eight multiples of 135° (mod 360°).
        let mut starts = Vec::new();
        for i in 0..64 {
            let spec = ScheduleSpec {
                pulse_rate_hz: 687_500.0 / 64.0,
                frame_rate_hz: 27.5,
                period_s: 1.0 / 27.5,
                phase_frac: (f64::from(i) + 0.5) / 65_536.0,
                ..paper(Sampling::Carla)
            };
            // m · 135° (mod 360°): the multiples of 45°.
            let deg = schedule(&spec).0[0].tau_s * 27.5 * 360.0;
            let k = (deg / 45.0).round();
            assert!((deg - 45.0 * k).abs() < 1e-6, "{deg}");
            starts.push(k as i64 % 8);
        }
        starts.sort_unstable();
        starts.dedup();
        assert_eq!(starts.len(), 8);
    }

    #[test]
    fn carla_async_ticks_vary_within_the_jitter_and_keep_carlas_rule() {
        let spec = paper(Sampling::CarlaAsync);
        let (pulses, t) = schedule(&spec);
        assert!(t >= 1.0);
        let mut ticks: Vec<u64> = pulses.iter().map(|p| p.tick).collect();
        ticks.dedup();
        let mut prev_end = 0.0;
        let mut counts = std::collections::BTreeSet::new();
        let mut u = 0.0f64;
        for &n in &ticks {
            let these: Vec<&Scheduled> = pulses.iter().filter(|p| p.tick == n).collect();
            let dt = these[0].tick_end_s - prev_end;
            assert!((0.04 - 1e-12..=0.06 + 1e-12).contains(&dt), "{dt}");
            let pts = points_per_laser(500_000, dt, 64) as usize;
            assert_eq!(these.len(), pts);
            counts.insert(pts);
            // CARLA's start angle and step, in turns.
            let step = 20.0 * dt / pts as f64;
            for (i, p) in these.iter().enumerate() {
                let want = (u + step * i as f64).fract();
                let got = p.tau_s / 0.05;
                let d = (want - got).abs();
                assert!(d.min(1.0 - d) < 1e-9, "{n} {i}");
            }
            u = (u + 20.0 * dt).fract();
            prev_end = these[0].tick_end_s;
        }
        assert!(counts.len() > 10, "{counts:?}");
    }

    #[test]
    fn drift_is_the_pulse_clock() {
        let spec = paper(Sampling::Drift);
        let (pulses, t) = schedule(&spec);
        assert_eq!(pulses.len(), 7812);
        assert_eq!(t, 7812.0 / 7812.5);
        // 390.625 pulses per tick: the pulses of tick 1 start at k = 391.
        assert_eq!(pulses[390].tick, 0);
        assert_eq!(pulses[391].tick, 1);
        // Pulse k at k/7812.5 s plus the phase 0.3 turns.
        for (k, p) in pulses.iter().enumerate().step_by(97) {
            let turns = k as f64 / 7812.5 / 0.05 + 0.3;
            assert_eq!(p.frame, turns.floor() as u64);
            assert!((p.tau_s / 0.05 - turns.fract()).abs() < 1e-9);
        }
    }
}
