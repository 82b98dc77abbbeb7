//! Tests that pin parts of the bound and the head no other core test reached
//! (`specs/mutants.md`, "`eye_safety/bound/*.rs` (the split bound)" and
//! "`eye_safety/head/*.rs`"). Each names the mutant it kills and works its
//! expected value out by hand.

use gaze_lidar_core::eye_safety::ael::APERTURE_IR_MM;
use gaze_lidar_core::eye_safety::bound::{Seg, WALK_MAX_PIECES};
use gaze_lidar_core::eye_safety::exposure::evaluate_segments_at_declared_distance;
use gaze_lidar_core::eye_safety::head::{Channel, Head};
use gaze_lidar_core::eye_safety::{evaluate_segments, EyeSafetyParams, Rule};

fn params(lambda_nm: f64, beam_mm: f64) -> EyeSafetyParams {
    EyeSafetyParams {
        wavelength_nm: lambda_nm,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: beam_mm,
        head: None,
    }
}

fn seg(start_deg: f64, width_deg: f64, power_w: f64, spin_rad_s: f64) -> Seg {
    Seg {
        start_deg,
        width_deg,
        power_w,
        spin_start_rad_s: spin_rad_s,
        spin_end_rad_s: spin_rad_s,
    }
}

/// The pass angle, rad, from its definition: the head turn while the
/// aperture centre, 100 mm from the axis, is within `(a + D)/2` of the ray,
/// `2·asin((a + D)/200)`.
fn pass_rad(aperture_mm: f64, beam_mm: f64) -> f64 {
    2.0 * ((aperture_mm + beam_mm) / 200.0).asin()
}

/// 1450 nm, 200 kHz, beam 1 mm: pass arc `2h = 2·asin((3.5571 + 1)/200)` rad
/// = 2.6113°. At 1 rad/s everywhere, 100 pairs of a hot bin (0.9 of a pair,
/// `p` W) and a cold one (0.1, dark) fill half the pass arc from 10°; the
/// rest is dark.
fn alternating_pass(p: f64) -> (Vec<Seg>, f64, f64) {
    let two_h_deg = pass_rad(APERTURE_IR_MM, 1.0).to_degrees();
    let region = 0.5 * two_h_deg;
    let pair = region / 100.0;
    let mut segs = vec![seg(0.0, 10.0, 0.0, 1.0)];
    let mut a = 10.0;
    for _ in 0..100 {
        segs.push(seg(a, 0.9 * pair, p, 1.0));
        segs.push(seg(a + 0.9 * pair, 0.1 * pair, 0.0, 1.0));
        a += pair;
    }
    segs.push(seg(a, 360.0 - a, 0.0, 1.0));
    (segs, region.to_radians(), (0.9 * pair).to_radians())
}

/// Kills `walks.rs` `Walks::walk`: `e + w.p_span * (l0 - l)` →
/// `e * w.p_span * (l0 - l)` (a walk longer than `WALK_MAX_PIECES` pieces
/// restarts its energy at 0, under-counting every long window inside one
/// pass). The hot region is 200 bins, ≈ 400 envelope pieces (a hot bin's
/// power lasts one spacing `Δ` past it, the 22.8 µs cold gaps outlast
/// `Δ` = 5 µs), so no walk crosses it within `WALK_MAX_PIECES` = 96.
///
/// By hand: the region lasts `T_A` = 0.022785 s (1.3055° at 1 rad/s); each
/// hot bin 2.0507e-4 s, so for any clock phase it holds at least
/// `⌊2.0507e-4 · 2e5⌋` = 41 pulses: 4100 pulses of `p·Δ` within a window
/// no longer than `T_A`, whose AEL is at most `4.4e-3·T_A^0.25` =
/// 1.70949e-3 J (1 ms – 0.35 s row, growing): at `p` = 0.08506 W the true
/// ratio is at least `4100 · 4.253e-7 / 1.70949e-3` = 1.0200. The whole
/// passes are longer (0.0456 s: the region plus dark) and lower.
#[test]
fn long_walk_inside_one_pass_is_not_under_counted() {
    assert_eq!(WALK_MAX_PIECES, 96);
    let (f_p, p) = (2e5, 0.08506);
    let (segs, t_a, t_hot) = alternating_pass(p);
    let per_bin = (t_hot * f_p).floor();
    assert_eq!(per_bin, 41.0);
    let truth_lb = 100.0 * per_bin * p / f_p / (4.4e-3 * t_a.powf(0.25));
    assert!((truth_lb - 1.0200).abs() < 1e-3, "{truth_lb}");
    let r = evaluate_segments(&segs, &params(1450.0, 1.0), f_p).unwrap();
    assert!(
        r.rule_ratios[1] >= truth_lb,
        "pass train {} below {truth_lb}",
        r.rule_ratios[1]
    );
    assert!(r.worst_ratio > 1.0);
}

/// Kills `laser.rs` `Laser::pass_count_max`: `((lo + tau) / frame_s).ceil()`
/// → `((lo - tau) / frame_s).ceil()` (when a pass lasts more than half a
/// frame the first step of a Table 3 row drops out of the candidates).
///
/// 1450 nm, beam 1 mm (`2h` = 0.045571 rad), `T_f` = 1/11 s: a slow arc of
/// `1.05·2h` at `ω_s = 2h/τ` with `τ = 0.9·T_f` = 0.081818 s, the rest of
/// the turn fast so the frame is 1/11 s; one power `p` throughout; 12.1 Hz
/// pulses, so `τ·f` = 0.99: a pass holds one pulse, `E⁺ = p·Δ`. Rule C
/// (at most `⌊(T + τ)/T_f⌋ + 1` passes in a window of `T`) steps up at
/// `T_k = k·T_f − τ`. The 0.35 s row edge: `(0.35 + τ)/T_f` = 4.75, so the
/// first step in the `1e-2·t` row is `k = 5`, `T_5` = 0.372727 s, six
/// passes: `6·p·Δ/(1e-2·T_5)` = 1609.76·`p·Δ`, larger than the edge itself
/// (5 passes over 3.3843e-3 J: 1477.4) and the last step of the row before
/// (`T_4` = 0.281818 s, 5 over `4.4e-3·T_4^0.25`: 1559.7). The mutant's
/// candidates are `k` = 3, 4 and the row's last two: it misses `k = 5`.
/// At `p·Δ` = 6.2742e-4 J the bound's figure is 1.0100; the mutant's
/// 0.9789 would certify it.
#[test]
fn pass_count_rule_evaluates_the_first_step_of_a_row() {
    let two_h = pass_rad(APERTURE_IR_MM, 1.0);
    let frame = 1.0 / 11.0;
    let tau = 0.9 * frame;
    let w_s = two_h / tau;
    let slow_deg = (1.05 * two_h).to_degrees();
    let slow_time = 1.05 * two_h / w_s;
    let w_f = (360.0 - slow_deg).to_radians() / (frame - slow_time);
    let f_p = 12.1;
    let e_pulse = 6.2742e-4;
    let p = e_pulse * f_p;
    let segs = vec![
        seg(0.0, slow_deg, p, w_s),
        seg(slow_deg, 360.0 - slow_deg, p, w_f),
    ];
    let t5 = 5.0 * frame - tau;
    let by_hand = 6.0 * e_pulse / (1e-2 * t5);
    assert!((by_hand - 1.0100).abs() < 1e-3, "{by_hand}");
    let r = evaluate_segments(&segs, &params(1450.0, 1.0), f_p).unwrap();
    assert!(
        r.worst_ratio >= by_hand,
        "{} below {by_hand}",
        r.worst_ratio
    );
    assert_eq!(r.binding_rule, Rule::T2Train);
}

fn valid_head(n: u32) -> Head {
    Head {
        cycle_s: 1e-3,
        origin_radius_mm: 40.0,
        origin_height_mm: 0.0,
        exit_diameter_mm: 5.0,
        divergence_mrad: 1.0,
        aperture_distance_mm: 100.0,
        channels: (0..n)
            .map(|id| Channel {
                id,
                elevation_deg: 0.0,
                azimuth_offset_deg: 0.0,
                slot_s: 0.0,
                power_scale: 1.0,
            })
            .collect(),
    }
}

/// `Err` naming `field`, or `Ok`.
fn verdict(h: &Head) -> Result<(), String> {
    h.validate().map_err(|e| e.field)
}

/// Kills the mutants of `Head::validate` (`head/mod.rs`) that move its one
/// numeric boundary. The head sample drew seven (lines as sampled):
/// 121:60 `>` → `>=` (512 channels refused), 139:13 `||` → `&&` (a crossing
/// point at or beyond the aperture accepted), 164:83 `<` → `>` (elevation),
/// 170:64 `delete !` (azimuth offset), 177:55 `delete !` and 177:66 `<` →
/// `==` (slot), 189:55 `==` → `!=` (duplicate ids). The core's tests built
/// only valid heads, so no refusal was pinned; an accepting mutant can lower
/// a figure (a negative `power_scale` subtracts from the overlap weights, a
/// crossing point at or beyond the aperture gives NaN footprints that meet
/// no aperture, a slot outside the cycle falls outside every window). Every
/// limit by hand from the documented boundary: accepted at its edge, refused
/// just beyond it, naming the field.
#[test]
fn head_validation_edges_by_hand() {
    let ok = |h: &Head| assert_eq!(verdict(h), Ok(()), "{h:?}");
    let refused = |h: &Head, field: &str| {
        assert_eq!(verdict(h), Err(field.to_owned()), "{h:?}");
    };
    let with = |f: &dyn Fn(&mut Head)| {
        let mut h = valid_head(2);
        f(&mut h);
        h
    };
    let ch = |f: &dyn Fn(&mut Channel)| with(&|h: &mut Head| f(&mut h.channels[1]));
    ok(&valid_head(1));
    ok(&valid_head(512));
    refused(&valid_head(0), "channels");
    refused(&valid_head(513), "channels");

    ok(&with(&|h| h.cycle_s = 1.0));
    for bad in [1.000_000_1, 0.0, -1e-3, f64::NAN, f64::INFINITY, 1e-310] {
        refused(&with(&|h| h.cycle_s = bad), "cycle_s");
    }
    ok(&with(&|h| h.aperture_distance_mm = 10_000.0));
    for bad in [10_000.001, 0.0, -100.0, f64::NAN] {
        refused(
            &with(&|h| h.aperture_distance_mm = bad),
            "aperture_distance_mm",
        );
    }
    ok(&with(&|h| h.origin_radius_mm = 0.0));
    ok(&with(&|h| h.origin_radius_mm = 99.999));
    for bad in [100.0, 100.001, 1e4, -1e-3, f64::NAN, f64::INFINITY] {
        refused(&with(&|h| h.origin_radius_mm = bad), "origin_radius_mm");
    }
    ok(&with(&|h| h.origin_height_mm = 1e4));
    ok(&with(&|h| h.origin_height_mm = -1e4));
    for bad in [10_000.01, -10_000.01, f64::NAN, f64::NEG_INFINITY] {
        refused(&with(&|h| h.origin_height_mm = bad), "origin_height_mm");
    }
    ok(&with(&|h| h.exit_diameter_mm = 999.9));
    for bad in [1000.0, 0.0, -5.0, f64::NAN] {
        refused(&with(&|h| h.exit_diameter_mm = bad), "exit_diameter_mm");
    }
    ok(&with(&|h| h.divergence_mrad = 0.0));
    ok(&with(&|h| h.divergence_mrad = 1000.0));
    for bad in [1000.1, -0.1, f64::NAN] {
        refused(&with(&|h| h.divergence_mrad = bad), "divergence_mrad");
    }

    for (edge, bad) in [(89.999, 90.0), (-89.999, -90.0)] {
        ok(&ch(&|c| c.elevation_deg = edge));
        refused(&ch(&|c| c.elevation_deg = bad), "channels[1].elevation_deg");
        ok(&ch(&|c| c.azimuth_offset_deg = edge));
        refused(
            &ch(&|c| c.azimuth_offset_deg = bad),
            "channels[1].azimuth_offset_deg",
        );
    }
    refused(
        &ch(&|c| c.elevation_deg = f64::NAN),
        "channels[1].elevation_deg",
    );
    refused(
        &ch(&|c| c.azimuth_offset_deg = f64::NAN),
        "channels[1].azimuth_offset_deg",
    );
    ok(&ch(&|c| c.slot_s = 0.999e-3));
    for bad in [1e-3, 2e-3, -1e-9, f64::NAN] {
        refused(&ch(&|c| c.slot_s = bad), "channels[1].slot_s");
    }
    ok(&ch(&|c| c.power_scale = 0.0));
    ok(&ch(&|c| c.power_scale = 1000.0));
    for bad in [1000.1, -0.1, -1.0, f64::NAN] {
        refused(&ch(&|c| c.power_scale = bad), "channels[1].power_scale");
    }

    // Ids: unique in any order; a repeated id is refused naming it.
    ok(&ch(&|c| c.id = 7));
    let mut h = valid_head(3);
    h.channels[0].id = 5;
    h.channels[2].id = 5;
    refused(&h, "channels (id 5)");
}

/// Kills `bound/mod.rs` `evaluate_with`: `two_h_deg: 2.0 * half_deg` →
/// `2.0 + half_deg` (the window walks reach `2° + h` instead of the pass arc
/// `2h`: for `h > 2°` a window inside one pass that is longer than `2° + h`
/// is never walked).
///
/// 1450 nm, beam 10 mm: `2h = (3.5571 + 10)/100` rad = 7.7676°, `h` =
/// 3.8838°; the mutant reaches 5.8838°. A hot sector of 7.5° at 1 rad/s
/// (`t_hot` = 0.1309 s, 100 kHz, power `p`), flanked by 1° dark sectors at
/// 2.336e-3 rad/s (the 0.27° a pass holds beyond the hot sector take 2 s, so
/// every whole pass that holds the sector lasts over 2 s and its figure is
/// about 8× lower); the rest of the turn dark at 1 rad/s. An aperture at the
/// sector's middle sees all of it (3.75° < `h`). By hand: any clock phase
/// puts at least `⌊t_hot · f⌋` = 13089 pulses of `p/f` within a window no
/// longer than `t_hot`, whose AEL is at most `4.4e-3 · t_hot^0.25` =
/// 2.64659e-3 J: at `p` = 0.020624 W the true ratio is at least 1.0200. The
/// mutant's longest walk holds at most 5.8838/7.5 of the sector, a figure
/// about `(5.8838/7.5)^0.75` = 0.83 of that (it certified).
#[test]
fn walk_spans_the_whole_pass_arc() {
    let two_h_deg = pass_rad(APERTURE_IR_MM, 10.0).to_degrees();
    assert!(two_h_deg > 4.0 + 1.5, "{two_h_deg}");
    let (f_p, p) = (1e5, 0.020624);
    let hot_deg = 7.5;
    let slow = (two_h_deg - hot_deg).to_radians() / 2.0;
    let segs = vec![
        seg(0.0, 100.0, 0.0, 1.0),
        seg(100.0, 1.0, 0.0, slow),
        seg(101.0, hot_deg, p, 1.0),
        seg(101.0 + hot_deg, 1.0, 0.0, slow),
        seg(102.0 + hot_deg, 258.0 - hot_deg, 0.0, 1.0),
    ];
    let t_hot = hot_deg.to_radians();
    let pulses = (t_hot * f_p).floor();
    assert_eq!(pulses, 13089.0);
    let truth_lb = pulses * p / f_p / (4.4e-3 * t_hot.powf(0.25));
    assert!((truth_lb - 1.0200).abs() < 1e-3, "{truth_lb}");
    let r = evaluate_segments(&segs, &params(1450.0, 10.0), f_p).unwrap();
    assert!(
        r.rule_ratios[1] >= truth_lb,
        "pass train {} below {truth_lb} ({:?})",
        r.rule_ratios[1],
        r.rule_ratios
    );
    assert!(r.worst_ratio > 1.0);
}

/// Kills `head/mod.rs` `one` → `0.0` / `-1.0` (a channel's `power_scale`
/// read as 0 or −1 when the file omits it: every such head would certify
/// with no energy) and `aperture_distance_default` → `0.0` / `1.0` / `-1.0`
/// (the aperture at the axis instead of 100 mm): the defaults a head file
/// gets for the fields it may omit, by the description (`power_scale` 1,
/// `origin_height_mm` 0, `aperture_distance_mm` 100).
#[test]
fn head_file_defaults_are_the_description_s() {
    let h: Head = serde_json::from_str(
        r#"{"cycle_s": 1e-3, "origin_radius_mm": 40.0, "exit_diameter_mm": 5.0,
            "divergence_mrad": 1.0,
            "channels": [{"id": 7, "elevation_deg": 0.0, "azimuth_offset_deg": 0.0,
                          "slot_s": 0.0}]}"#,
    )
    .unwrap();
    assert_eq!(h.channels[0].power_scale, 1.0);
    assert_eq!(h.origin_height_mm, 0.0);
    assert_eq!(h.aperture_distance_mm, 100.0);
    h.validate().unwrap();
}

/// Kills `bound/mod.rs` `evaluate_with`: `pulses_j: best.e_max.0 + e_pad` →
/// `best.e_max.0 - e_pad` (the pass energy handed to the multi-pass rules
/// loses the bound on the rounding of the envelope integrals instead of
/// gaining it), and its two neighbours on the other pass figures
/// (`envelope_j: e_env_max + e_pad`, `duration_s: τ_max + t_pad`).
///
/// Every energy the bound computes is a difference of integrals from 0°, so
/// it may be off by `energy_rounding_j` ≥ `2·P̂·64ε·T_f` (the margin table
/// in `bound/count.rs`), and every duration by `64ε·T_f`: the pass figures
/// the multi-pass rules use must exceed the largest pass energy and the
/// longest pass by at least those. On the near-stopped frame of
/// `tests/it/eye_safety/time_rounding.rs` (905 nm, 152 kHz, 16.2 mW over 20° at
/// 600 rad/s, 340° dark at 2.6e-6 rad/s) by hand: `T_f` =
/// `0.349066/600 + 5.934119/2.6e-6` = 2.282353·10⁶ s, so the pads are at
/// least `2 · 16.2e-3 W · 64ε · T_f` = 1.0509·10⁻⁹ J (1 % of one pulse's
/// 1.0658·10⁻⁷ J) and `64ε · T_f` = 3.2434·10⁻⁸ s.
#[test]
fn multi_pass_figures_carry_the_rounding_pads() {
    use gaze_lidar_core::eye_safety::bound;
    use gaze_lidar_core::eye_safety::exposure::{laser, pass_angle_deg};
    let (f_p, p) = (152e3, 16.2e-3);
    let segs = vec![seg(0.0, 340.0, 0.0, 2.6e-6), seg(340.0, 20.0, p, 600.0)];
    let frame_s = 20f64.to_radians() / 600.0 + 340f64.to_radians() / 2.6e-6;
    assert!((frame_s / 2.282_353e6 - 1.0).abs() < 1e-6, "{frame_s}");
    let t_pad = 64.0 * f64::EPSILON * frame_s;
    let e_pad = 2.0 * p * t_pad;
    assert!((e_pad / 1.0509e-9 - 1.0).abs() < 1e-4, "{e_pad}");
    let prm = params(905.0, 0.5);
    let l = laser(&prm, f_p).unwrap();
    let b = bound::evaluate(&segs, 0.5 * pass_angle_deg(&prm, &l), &l);
    assert!(
        b.pass.pulses_j >= b.max_pass_energy_j + e_pad,
        "{:?} over {}",
        b.pass,
        b.max_pass_energy_j
    );
    assert!(
        b.pass.envelope_j >= b.max_pass_energy_j + e_pad,
        "{:?} over {}",
        b.pass,
        b.max_pass_energy_j
    );
    assert!(
        b.pass.duration_s >= b.max_pass_duration_s + t_pad,
        "{:?} over {}",
        b.pass,
        b.max_pass_duration_s
    );
}

/// Kills two mutants of `bound/cells.rs` `Cells::sweep`'s Rule 1 at a cell
/// end that touches a hot bin: `tau_touch = 8s/ω_min + t_slack` →
/// `8s/ω_min · t_slack` (the touching pass's duration without the growth
/// over the `2s` the cut may be off, `s` = `TOUCH_SNAP_DEG` = 1e-9°), and
/// `p_near`'s arc end `θ + h + 3s` → `(θ + h)·3s` (the hottest bin near a
/// cut read from the pass's left end only, so a hot bin touched by the
/// right edge is missed there).
///
/// The bound snaps every pass edge by `s` (the cuts are computed, so an
/// aperture within `2s` of a touch cut may be the one that touches): Rule 1
/// covers every aperture within `2s` of a cut with the bins touched there.
/// 905 nm, beam 0.5 mm: `2h` = `2·asin(0.0375)` = 0.0750176 rad (4.2982°). A dark bin
/// `[0°, 10°)` at `ω_S` = 1e-3 rad/s, a dark bin `[10°, 10° + a)` and a hot
/// one (`p`) of 5° after it at `ω_A` = 100 rad/s, the rest dark at
/// `ω_A`; `a = 2h − δ`, `δ` = 5e-4°. The aperture at `θ_c = 10° + a − h`
/// touches the hot bin with its right edge while its left edge is `δ`
/// inside the slow bin: `τ_c = δ/ω_S + a/ω_A` = 9.476735e-3 s (passes to
/// the right, into the hot bin, are shorter: the left edge leaves the slow
/// bin). `f_p` puts `τ_c·f_p` at 948 − 1.5e-3: 948 pulses. The aperture
/// `2s` before the cut: `τ = τ_c + 2s·(1/ω_S − 1/ω_A)` = τ_c + 3.4906e-8 s,
/// `τ·f_p` = 948.0020: 949 pulses for some phase, one pass within T2
/// (`T_f` = 174.6 s), so C5 = `5·949^-0.25` = 0.900852 and Rule 1 =
/// `p·Δ / (7.7e-8 J·C4·C5)`, C4 = `10^0.41`. At `p·Δ` set for 1.0001 the
/// mutants count 948 pulses there (C5 `5·948^-0.25`): 0.99984.
#[test]
fn rule_one_counts_the_touching_pass_within_the_snap() {
    use gaze_lidar_core::eye_safety::exposure::{laser, pass_angle_deg};
    let prm = params(905.0, 0.5);
    let two_h = pass_rad(7.0, 0.5);
    let two_h_deg = f64::to_degrees(two_h);
    let (w_s, w_a) = (1e-3, 100.0);
    let delta_deg = 5e-4;
    let a_deg = two_h_deg - delta_deg;
    let tau_c = delta_deg.to_radians() / w_s + a_deg.to_radians() / w_a;
    assert!((tau_c / 9.476735e-3 - 1.0).abs() < 1e-6, "{tau_c}");
    let f_p = (948.0 - 1.5e-3) / tau_c;
    assert!(f_p < 2e5, "one pulse per T_i group: {f_p}");
    let s_rad = 1e-9f64.to_radians();
    let tau = tau_c + 2.0 * s_rad * (1.0 / w_s - 1.0 / w_a);
    let pulses = (tau * f_p).floor() + 1.0;
    assert_eq!(pulses, 949.0);
    let c5 = 5.0 * pulses.powf(-0.25);
    assert!((c5 - 0.900_852).abs() < 1e-6, "{c5}");
    let ael_j = 7.7e-8 * 10f64.powf(0.41) * c5;
    let e_pulse = 1.0001 * ael_j;
    let p = e_pulse * f_p;
    let hot = 10.0 + a_deg;
    let segs = vec![
        seg(0.0, 10.0, 0.0, w_s),
        seg(10.0, a_deg, 0.0, w_a),
        seg(hot, 5.0, p, w_a),
        seg(hot + 5.0, 355.0 - hot, 0.0, w_a),
    ];
    let l = laser(&prm, f_p).unwrap();
    assert!((pass_angle_deg(&prm, &l) / two_h_deg - 1.0).abs() < 1e-11);
    let truth = e_pulse / ael_j;
    let r = evaluate_segments(&segs, &prm, f_p).unwrap();
    assert!(
        r.rule_ratios[0] >= truth,
        "Rule 1 {} below {truth} ({:?})",
        r.rule_ratios[0],
        r.rule_ratios
    );
}

/// Kills `bound/laser.rs` `Laser::time_base_ratio`: `e / self.ael_j(tb)` →
/// `e * self.ael_j(tb)` (the time-base figure, energy times the AEL
/// instead of over it: at 905 nm, where `AEL(100 s)` = 0.1 J, a hundredth
/// of the figure). It is the reported `rule_ratios[3]` whenever the
/// multi-pass rule binds at a window of at most T2 (then its figure is
/// `rule_ratios[2]`), as here.
///
/// By hand: 905 nm, beam 0.5 mm (`2h` = 0.075 rad), 0.2 Hz at constant
/// spin (`ω` = 0.4π rad/s), 1 mW throughout, 100 kHz. Every pass lasts
/// `0.075/0.4π` = 0.0596831 s, so it holds at least `⌊5968.31⌋` = 5968
/// pulses of 1e-8 J for any clock phase; a 100 s window holds at least
/// `⌊(100 − τ)/5⌋` = 19 whole passes. `AEL(100 s)` = `3.9e-4 · C4 · 100`
/// = 0.100246 J (C4 = `10^0.41`): the time-base ratio is at least
/// `19 · 5968 · 1e-8 / 0.100246` = 0.011311. (The multi-pass rule binds
/// at two passes in a window just under one frame, `2/T^0.75` against the
/// time base's `≈ T/T_f`: T2 train.)
#[test]
fn time_base_ratio_is_energy_over_the_ael() {
    let (f_p, p) = (1e5, 1e-3);
    let w = 0.4 * std::f64::consts::PI;
    let segs = vec![seg(0.0, 180.0, p, w), seg(180.0, 180.0, p, w)];
    let tau = 0.075 / w;
    let per_pass = (tau * f_p).floor();
    assert_eq!(per_pass, 5968.0);
    let passes = ((100.0 - tau) / 5.0).floor();
    assert_eq!(passes, 19.0);
    let ael_tb = 3.9e-4 * 10f64.powf(0.41) * 100.0;
    assert!((ael_tb - 0.100_246).abs() < 1e-6, "{ael_tb}");
    let truth_lb = passes * per_pass * p / f_p / ael_tb;
    assert!((truth_lb - 0.011_311).abs() < 1e-6, "{truth_lb}");
    let r = evaluate_segments(&segs, &params(905.0, 0.5), f_p).unwrap();
    assert!(
        r.rule_ratios[3] >= truth_lb,
        "time base {} below {truth_lb} ({:?})",
        r.rule_ratios[3],
        r.rule_ratios
    );
}

/// Kills `bound/whole_pass.rs` `Cells::full_pass`: `t_err / (hi - lo)` →
/// `t_err / (hi / lo)` (the spread that widens a whole-pass energy
/// interpolated at a Table 3 row edge for the error of the pass durations
/// at the cell's cuts shrinks from `t_err/(hi − lo)` of the cell's energy
/// change to about `t_err` of it).
///
/// The stated margin (`specs/eye_safety.md`, "Whole-pass windows"; the
/// margin table of `bound/count.rs`): the durations at the cuts may be off
/// by `t_err = 2·PRUNE_SLACK·T_f` (`PRUNE_SLACK` = 1e-12), so the azimuth
/// where `τ` meets a row edge `t_e` is uncertain and the figure there must
/// cover `E(t_e) + |dE/dτ|·t_err` over the AEL at `t_e`: the energy of
/// every pass whose duration is within `t_err` of the edge.
///
/// By hand: 1450 nm, beam 1 mm (`2h` = 0.045571 rad), 10 kHz, power `p` on
/// `[340°, 350°)` at `ω₁ = 2h/0.3` and on `[350°, 360°)` at `ω₂ = 2h/0.4`,
/// dark on `[0°, 340°)` at `ω_d` such that `T_f` = 10⁵ s (`t_err` =
/// 2·10⁻⁷ s). A pass straddling 350° lasts `τ` from 0.3 s to 0.4 s, affine
/// in the azimuth, and holds `E = p·(τ + Δ)` (lit throughout): `dE/dτ = p`.
/// It meets the 0.35 s edge at 350°, where the AEL is the smaller row,
/// `4.4e-3·0.35^0.25` = 3.38431e-3 J (the `10⁻²·t` row beyond is 3.5e-3 J
/// and falls in `E/τ`; the row before rises in `E/τ^0.25`): the pass-train
/// figure binds there at `p·(0.35 + Δ + t_err)/3.38431e-3`. The mutant's
/// spread covers `p·t_err·(hi − lo)·lo/hi` ≤ 0.1·`p·t_err`: its figure is
/// about 5·10⁻⁷ (relative) lower, ten times what the ratio margin and the
/// energy rounding pad add.
#[test]
fn whole_pass_figure_at_a_row_edge_covers_the_cut_error() {
    use gaze_lidar_core::eye_safety::bound;
    use gaze_lidar_core::eye_safety::exposure::{laser, pass_angle_deg};
    let prm = params(1450.0, 1.0);
    let (f_p, p) = (1e4, 1e-3);
    let two_h = pass_rad(APERTURE_IR_MM, 1.0);
    let (w1, w2) = (two_h / 0.3, two_h / 0.4);
    let ten = 10f64.to_radians();
    let frame_s = 1e5;
    let w_d = 340f64.to_radians() / (frame_s - ten / w1 - ten / w2);
    let segs = vec![
        seg(0.0, 340.0, 0.0, w_d),
        seg(340.0, 10.0, p, w1),
        seg(350.0, 10.0, p, w2),
    ];
    let l = laser(&prm, f_p).unwrap();
    let half_deg = 0.5 * pass_angle_deg(&prm, &l);
    assert!((2.0 * half_deg / two_h.to_degrees() - 1.0).abs() < 1e-11);
    let t_err = 2.0 * 1e-12 * frame_s;
    let ael_edge = 4.4e-3 * 0.35f64.powf(0.25);
    assert!((ael_edge / 3.38431e-3 - 1.0).abs() < 1e-5, "{ael_edge}");
    let covered = p * (0.35 + 1.0 / f_p + t_err) / ael_edge;
    let b = bound::evaluate(&segs, half_deg, &l);
    assert!(
        (b.rule_windows_s[0] - 0.35).abs() < 1e-12,
        "{:?}",
        b.rule_windows_s
    );
    assert!(
        b.ratios[1] >= covered,
        "pass train {} below {covered} ({:?})",
        b.ratios[1],
        b.ratios
    );
}

/// Kills `bound/whole_pass.rs` `Cells::full_pass`: `tu + dt * w` →
/// `tu + dt + w` and `tu + dt / w` (the duration of the whole pass where
/// its energy reaches the cap `E⁺` lands at or beyond the cell's longer
/// end, so the cap's kink, where `min(E, E⁺)/AEL(τ)` is largest, is
/// evaluated at a longer window and a larger AEL).
///
/// By the definition (`specs/eye_safety.md`, "Whole-pass windows"): the
/// figure is at least `min(E(φ), E⁺)/AEL_inf(τ(φ))` at every azimuth `φ`,
/// with `E⁺` the bound's largest pulse energy of a pass (read back, and
/// checked against the 20 pulses below). 1450 nm, beam 1 mm (`2h` =
/// 0.045571 rad), 99.5 Hz (`Δ` = 10.05 ms): `2p` on `[0°, 10°)` at
/// `ω_A = 2h/0.01`, `p` on `[10°, 350°)` at `ω_B = 2h/0.2`, dark on
/// `[350°, 360°)` at `ω_A` (so that only the passes leaving the hot sector,
/// whose cells run from the short to the long pass, reach `E⁺`; the passes
/// entering it hold under `0.05·p`). A pass with a share `x` of its arc in
/// the hot sector lasts `τ = 0.01x + 0.2(1 − x)`
/// and its envelope holds `E = 2p(0.01x + Δ) + p·0.2(1 − x)` (the max
/// filter keeps `2p` for `Δ` after the sector): `E` grows with `τ`, and so
/// does `E/τ^0.25` (the `4.4e-3·t^0.25` row) until `E` reaches `E⁺`. For
/// `x` just above 0 a clock phase puts one pulse in the hot sector and 19
/// after it within `19Δ` = 0.190955 s: `E⁺ ≥ (2 + 19)·p·Δ`, below
/// `E(0)` = 0.22010·`p`. With `E⁺` = 21·`p·Δ`, `E` reaches it at `x_c` =
/// 0.0503, `τ_c` = 0.190452 s: the figure is at least `E⁺/(4.4e-3·τ_c^0.25)`.
/// Those 20 pulses alone are a true exposure of `21·p·Δ` in a window of
/// `19Δ`: the true worst ratio is at least `21·p·Δ/(4.4e-3·(19Δ)^0.25)`
/// (1 − 6.6·10⁻⁴ of the kink's figure). The mutants evaluate the cap at
/// `τ ≥ 0.2` s and report the longest pass's `E⁺/AEL(0.2 s)`, 1.2 % below
/// the kink and below that true exposure (0.07173 against 0.07256 at
/// `p` = 1 mW; applied by hand, both fail here).
#[test]
fn whole_pass_figure_takes_the_cap_s_kink() {
    use gaze_lidar_core::eye_safety::bound;
    use gaze_lidar_core::eye_safety::exposure::{laser, pass_angle_deg};
    let prm = params(1450.0, 1.0);
    let (f_p, p) = (99.5, 1e-3);
    let delta = 1.0 / f_p;
    let two_h = pass_rad(APERTURE_IR_MM, 1.0);
    let (tau_a, tau_b) = (0.01, 0.2);
    let segs = vec![
        seg(0.0, 10.0, 2.0 * p, two_h / tau_a),
        seg(10.0, 340.0, p, two_h / tau_b),
        seg(350.0, 10.0, 0.0, two_h / tau_a),
    ];
    let l = laser(&prm, f_p).unwrap();
    let half_deg = 0.5 * pass_angle_deg(&prm, &l);
    assert!((2.0 * half_deg / two_h.to_degrees() - 1.0).abs() < 1e-11);
    let b = bound::evaluate(&segs, half_deg, &l);
    let e_cap = b.max_pass_energy_j;
    let twenty = 21.0 * p * delta;
    assert!((19.0 * delta - 0.190_955).abs() < 1e-6);
    let e_env = |x: f64| 2.0 * p * (tau_a * x + delta) + p * tau_b * (1.0 - x);
    assert!((e_env(0.0) / p - 0.220_10).abs() < 1e-5);
    assert!(
        e_cap >= twenty && e_cap < e_env(0.0),
        "E⁺ {e_cap}, 20 pulses {twenty}, E(0) {}",
        e_env(0.0)
    );
    // `E(x_c) = E⁺`, `E` affine in `x`.
    let x_c = (e_env(0.0) - e_cap) / (e_env(0.0) - e_env(1.0));
    let tau_c = tau_a * x_c + tau_b * (1.0 - x_c);
    if e_cap == twenty {
        assert!((x_c - 0.0503).abs() < 1e-4, "{x_c}");
        assert!((tau_c - 0.190_452).abs() < 1e-6, "{tau_c}");
    }
    let truth_lb = twenty / (4.4e-3 * (19.0 * delta).powf(0.25));
    assert!(
        b.ratios[1] >= truth_lb,
        "pass train {} below 20 pulses in 19Δ: {truth_lb}",
        b.ratios[1]
    );
    let kink = e_cap / (4.4e-3 * tau_c.powf(0.25));
    assert!(
        b.ratios[1] >= kink,
        "pass train {} below {kink} at {tau_c} s ({:?}, {:?})",
        b.ratios[1],
        b.ratios,
        b.rule_windows_s
    );
}

/// Kills `head/overlap.rs` `vertical` and `vertical_slots`: the interval's
/// upper end `z + h + TOUCH_MM` → `z + h − TOUCH_MM` (two channels whose height
/// intervals miss by less than `2·TOUCH_MM` no longer meet one aperture
/// height, so `W_v`, the weight every energy rule of the head multiplies,
/// can fall to one channel's, and `S_v`, which bounds the head's pulse
/// count for C5, to one slot: a smaller count is a larger C5).
///
/// The stated widening (`overlap::TOUCH_MM`, 1e-9 mm): every interval end
/// moves out by it, so positions that touch in exact arithmetic but miss by
/// a rounding error still meet; two intervals `2·TOUCH_MM` or less apart
/// meet. By hand: `[−5, 5]` and `[5 + 1.5e-9, 15 + 1.5e-9]` (half-height
/// 5 mm): 1.5e-9 mm apart, so both channels count (weight `2·(1 + 1e-12)`);
/// 3e-9 mm apart, only one does. The same for two distinct slots.
#[test]
fn vertical_overlap_meets_within_the_touch_widening() {
    use gaze_lidar_core::eye_safety::head::geometry::Footprint;
    use gaze_lidar_core::eye_safety::head::overlap::{
        vertical, vertical_slots, SUM_MARGIN, TOUCH_MM,
    };
    assert_eq!(TOUCH_MM, 1e-9);
    let fp = |z_mm: f64| Footprint {
        index: 0,
        psi_rad: 0.0,
        z_mm,
        slant_mm: 100.0,
        width_mm: 3.0,
        cos_beta: 1.0,
        half_arc_mm: 5.0,
        half_height_mm: 5.0,
        pass_angle_deg: 0.1f64.to_degrees(),
    };
    let m = vertical(&[fp(0.0), fp(10.0 + 1.5e-9)], &[1.0, 1.0]);
    assert_eq!(m.count, 2, "{m:?}");
    assert_eq!(m.weight, 2.0 * (1.0 + SUM_MARGIN), "{m:?}");
    let m = vertical(&[fp(0.0), fp(10.0 + 3e-9)], &[1.0, 1.0]);
    assert_eq!(m.count, 1, "{m:?}");
    assert_eq!(m.weight, 1.0, "{m:?}");
    // `S_v`, the distinct firing slots meeting one height (the head's pulse
    // count for C5), with the same widening.
    assert_eq!(
        vertical_slots(&[fp(0.0), fp(10.0 + 1.5e-9)], &[0.0, 1e-5]),
        2
    );
    assert_eq!(vertical_slots(&[fp(0.0), fp(10.0 + 3e-9)], &[0.0, 1e-5]), 1);
}

/// The figures of `head` that `head/bound.rs` `head_overlaps` keeps per
/// thread (`HeadOverlaps`: everything of `HeadFigures` but what the spin,
/// the channel count, the cycle and the aperture distance add), and the whole
/// `HeadFigures`, both as text, evaluated in the calling thread.
fn figures_here(head: &Head, wavelength_nm: f64, pulse_duration_s: f64) -> (String, String) {
    let p = EyeSafetyParams {
        wavelength_nm,
        pulse_duration_s,
        beam_diameter_mm: 5.0,
        head: Some(head.clone()),
    };
    let segs = [seg(0.0, 360.0, 1e-3, 10.0)];
    let r = evaluate_segments_at_declared_distance(&segs, &p, 1.0 / head.cycle_s).unwrap();
    let f = r.head.expect("head figures");
    let kept = format!(
        "{:?}",
        (
            (f.channels_at_worst, f.worst_height_mm),
            (f.weight_vertical, f.count_vertical, f.slots_vertical),
            f.union_passes,
            (f.weight_simultaneous, f.count_simultaneous),
            (f.weight_stalled, f.count_stalled),
            (f.weight_stalled_group, f.stalled_group_spans_time),
            (f.footprint_max_mm, f.pass_angle_deg, f.power_scale_max),
            &f.separations,
        )
    );
    (kept, format!("{f:?}"))
}

/// [`figures_here`] of `head` in a fresh thread (an empty memo), after
/// `before` (if any) with the same laser.
fn overlaps_after(
    before: Option<&Head>,
    head: &Head,
    wavelength_nm: f64,
    pulse_duration_s: f64,
) -> (String, String) {
    let (before, head) = (before.cloned(), head.clone());
    std::thread::spawn(move || {
        if let Some(b) = &before {
            figures_here(b, wavelength_nm, pulse_duration_s);
        }
        figures_here(&head, wavelength_nm, pulse_duration_s)
    })
    .join()
    .unwrap()
}

/// Kills the mutants of `head/bound.rs` `same_bits` and `head_overlaps`, the
/// per-thread memo of a head's overlap figures, that let one head (or one
/// aperture, or one grouping window) take the figures kept for another:
/// `same_bits` → `true`, an `&&` of its chain of field comparisons → `||`,
/// a field's `==` → `!=`, and the memo's aperture and window comparisons.
/// Figures of another head can be lower (a smaller `W_v`, `K_v`, `S_v`,
/// fewer union passes), and a stream or an optimizer run evaluates many
/// heads in one thread.
///
/// By construction, no value worked out: each variant of a three-channel
/// head changes one field (or the laser's aperture alone, or its grouping
/// window alone), and its kept figures, evaluated alone in a fresh thread,
/// differ from the base head's (asserted, so a memo that returned the base
/// head's would show); evaluated right after the base head in one thread,
/// its whole `HeadFigures` is the one it has alone. Not pinned here:
/// `Channel::id` (not an input of the figures: two heads that differ only in
/// ids may share them) and `cycle_s` (on this head no kept figure depends
/// on it; `specs/mutants.md`).
#[test]
fn head_memo_keeps_each_head_s_own_figures() {
    let base = Head {
        cycle_s: 1e-5,
        origin_radius_mm: 40.0,
        origin_height_mm: 0.0,
        exit_diameter_mm: 5.0,
        divergence_mrad: 1.0,
        aperture_distance_mm: 100.0,
        channels: [
            (0.0, 0.0, 0.0, 1.0),
            (0.5, 0.2, 1e-6, 0.8),
            (1.0, 0.4, 2e-6, 0.6),
        ]
        .iter()
        .enumerate()
        .map(
            |(i, &(elevation_deg, azimuth_offset_deg, slot_s, power_scale))| Channel {
                id: i as u32,
                elevation_deg,
                azimuth_offset_deg,
                slot_s,
                power_scale,
            },
        )
        .collect(),
    };
    let variant = |f: &dyn Fn(&mut Head)| {
        let mut h = base.clone();
        f(&mut h);
        h
    };
    let heads: Vec<(&str, Head)> = vec![
        ("origin_radius_mm", variant(&|h| h.origin_radius_mm = 20.0)),
        ("origin_height_mm", variant(&|h| h.origin_height_mm = 3.0)),
        ("exit_diameter_mm", variant(&|h| h.exit_diameter_mm = 6.0)),
        ("divergence_mrad", variant(&|h| h.divergence_mrad = 2.0)),
        (
            "aperture_distance_mm",
            variant(&|h| h.aperture_distance_mm = 150.0),
        ),
        (
            "channels (one more)",
            variant(&|h| {
                let mut c = h.channels[2].clone();
                c.id = 3;
                c.slot_s = 3e-6;
                h.channels.push(c);
            }),
        ),
        (
            "elevation_deg",
            variant(&|h| h.channels[2].elevation_deg = 20.0),
        ),
        (
            "azimuth_offset_deg",
            variant(&|h| h.channels[2].azimuth_offset_deg = 30.0),
        ),
        ("slot_s", variant(&|h| h.channels[1].slot_s = 0.0)),
        ("power_scale", variant(&|h| h.channels[2].power_scale = 0.9)),
    ];
    // The base head: 905 nm, 5 ns (aperture 7 mm, window T_i = 5 µs).
    let (base_kept, _) = overlaps_after(None, &base, 905.0, 5e-9);
    let mut wrong = Vec::new();
    for (field, h) in &heads {
        let (kept, alone) = overlaps_after(None, h, 905.0, 5e-9);
        if kept == base_kept {
            wrong.push(format!(
                "{field}: the variant's figures are the base head's: {kept}"
            ));
        }
        let (_, after) = overlaps_after(Some(&base), h, 905.0, 5e-9);
        if after != alone {
            wrong.push(format!(
                "{field}: after the base head {after}, alone {alone}"
            ));
        }
    }
    // The same head with another aperture alone (905 nm, 7 mm, and 1450 nm,
    // APERTURE_IR_MM; both with a window of the pulse duration, 6 µs > T_i)
    // and with another window alone (1450 nm: the pulse duration, 5 ns and
    // 3 µs).
    for (what, (l0, t0), (l1, t1)) in [
        ("aperture", (905.0, 6e-6), (1450.0, 6e-6)),
        ("window", (1450.0, 5e-9), (1450.0, 3e-6)),
    ] {
        let (k0, _) = overlaps_after(None, &base, l0, t0);
        let (k1, alone) = overlaps_after(None, &base, l1, t1);
        if k0 == k1 {
            wrong.push(format!("{what}: the figures do not depend on it: {k0}"));
        }
        let b = base.clone();
        let (_, after) = std::thread::spawn(move || {
            figures_here(&b, l0, t0);
            figures_here(&b, l1, t1)
        })
        .join()
        .unwrap();
        if after != alone {
            wrong.push(format!(
                "{what}: after the other laser {after}, alone {alone}"
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// Kills `eye_safety/exposure.rs` `evaluate_head`: `declared.worst_ratio >
/// standard.worst_ratio` → `>=` (a tie of the declared surface's worst
/// ratio with the 100 mm surface's took the declared report; the rule, as
/// specified, is that ties take the 100 mm report, so a verdict's worst
/// position, pass angle and rule figures are the Condition 3 surface's).
///
/// One radial channel from the axis (10 mm exit beam, no divergence), 905 nm,
/// 5 ns, 1 kHz (cycle 1 ms), 1 mW, uniform 1000 rad/s; declared at 200 mm.
/// By hand: one pass is `2·asin(8.5/R)` rad, 9.7521° (0.17 ms) at 100 mm and
/// 4.8716° (0.085 ms) at 200 mm; both are shorter than the 1 ms between
/// pulses, so at either distance a pass holds at most one pulse, every
/// pulse count behind Rule 1's C5 is the same and Rule 1 (binding on both
/// surfaces) gives the same figure: the two worst ratios tie, bit for bit,
/// while the reports differ (the pass angle).
#[test]
fn a_tie_of_both_surfaces_takes_the_100_mm_report() {
    let f_p = 1000.0;
    let at = |aperture_distance_mm: f64| {
        let mut p = params(905.0, 10.0);
        p.head = Some(Head {
            cycle_s: 1.0 / f_p,
            origin_radius_mm: 0.0,
            origin_height_mm: 0.0,
            exit_diameter_mm: 10.0,
            divergence_mrad: 0.0,
            aperture_distance_mm,
            channels: vec![Channel {
                id: 0,
                elevation_deg: 0.0,
                azimuth_offset_deg: 0.0,
                slot_s: 0.0,
                power_scale: 1.0,
            }],
        });
        p
    };
    let segs = [seg(0.0, 360.0, 1e-3, 1000.0)];
    let declared = evaluate_segments_at_declared_distance(&segs, &at(200.0), f_p).unwrap();
    let standard = evaluate_segments(&segs, &at(100.0), f_p).unwrap();
    assert_eq!(declared.binding_rule, Rule::SinglePulse);
    assert_eq!(standard.binding_rule, Rule::SinglePulse);
    assert_eq!(
        declared.worst_ratio.to_bits(),
        standard.worst_ratio.to_bits(),
        "no tie: {} vs {}",
        declared.worst_ratio,
        standard.worst_ratio
    );
    let pass_deg = |r: f64| (2.0 * (8.5 / r).asin()).to_degrees();
    assert!((standard.pass_angle_deg - pass_deg(100.0)).abs() < 1e-9);
    assert!((declared.pass_angle_deg - pass_deg(200.0)).abs() < 1e-9);
    let verdict = evaluate_segments(&segs, &at(200.0), f_p).unwrap();
    assert_eq!(verdict, standard);
}

/// Kills `head/overlap.rs` `pulses_in`: `first > window_s + eps` → `>=`
/// (and → `==`): a pulse exactly at the widened end of the window (`eps` =
/// 1e-9 of a cycle past `t0 + window`) is counted, as every touching end is
/// rounded up; the mutant drops it, one pulse fewer in a firing group (the
/// head's `W_inst`, `W_T` and their `multi_time` flag).
///
/// By hand: a clock of period 1 s at phase `0.25 + 1e-9` s, the closed
/// window `[0, 0.25]`: `eps` = 1e-9 s, so the pulse at `0.25 + 1e-9` is at
/// the widened end `0.25 + eps` (the same float), counted: 1. The next float
/// past it is outside: 0. The same pulse a cycle later is inside a window of
/// `1.25` s: 2.
#[test]
fn pulses_in_counts_a_pulse_at_the_widened_window_end() {
    use gaze_lidar_core::eye_safety::head::overlap::pulses_in;
    let (t0_s, window_s, cycle_s) = (0.0, 0.25, 1.0);
    let slot_s = 0.25 + 1e-9;
    assert_eq!(slot_s, window_s + 1e-9 * cycle_s);
    assert_eq!(pulses_in(slot_s, t0_s, window_s, cycle_s), 1);
    let beyond = f64::from_bits(slot_s.to_bits() + 1);
    assert_eq!(pulses_in(beyond, t0_s, window_s, cycle_s), 0);
    assert_eq!(pulses_in(slot_s, t0_s, 1.25, cycle_s), 2);
}

/// Kills `head/overlap.rs` `multi_time_overlap`: `k > 1` → `k < 1` (a
/// channel firing twice or more within one grouping window no longer marks
/// the group as spanning time, so, with no two slots meeting, the head's
/// Rule 1 drops its group term `W_g·E/(C5·AEL)` and keeps only the
/// one-instant term: at two channels fired together, fired `k` times in the
/// window, a figure `k` times too low).
///
/// By hand: one footprint, weight 1, slot 0, a clock of period 1 µs and
/// the closed window `[0, 2.5 µs]`: pulses at 0, 1 and 2 µs, `k` = 3 (weight
/// 3, one channel); the position receives pulses of three times, so the
/// group spans time. Two such footprints in one place with one slot: weight
/// 6, two channels, spanning time. A window of half a cycle holds one pulse
/// each: weight 2, not spanning time (one slot).
#[test]
fn a_channel_firing_twice_in_the_window_spans_time() {
    use gaze_lidar_core::eye_safety::head::geometry::Footprint;
    use gaze_lidar_core::eye_safety::head::overlap::{group, SUM_MARGIN};
    let fp = Footprint {
        index: 0,
        psi_rad: 0.0,
        z_mm: 0.0,
        slant_mm: 100.0,
        width_mm: 3.0,
        cos_beta: 1.0,
        half_arc_mm: 5.0,
        half_height_mm: 5.0,
        pass_angle_deg: 0.1f64.to_degrees(),
    };
    let circ = std::f64::consts::TAU * 100.0;
    let (m, spans) = group(&[fp], &[1.0], &[0.0], 1e-6, 2.5e-6, 0.0, circ);
    assert_eq!((m.weight, m.count), (3.0, 1), "{m:?}");
    assert!(spans, "three pulses of one channel in one window");
    let two = [fp, Footprint { index: 1, ..fp }];
    let (m, spans) = group(&two, &[1.0, 1.0], &[0.0, 0.0], 1e-6, 2.5e-6, 0.0, circ);
    assert_eq!(m.count, 2, "{m:?}");
    assert!(
        m.weight >= 6.0 && m.weight <= 6.0 * (1.0 + 2.0 * SUM_MARGIN),
        "{m:?}"
    );
    assert!(spans, "three pulses of each of two channels in one window");
    let (m, spans) = group(&two, &[1.0, 1.0], &[0.0, 0.0], 1e-6, 0.5e-6, 0.0, circ);
    assert_eq!(m.count, 2, "{m:?}");
    assert!(!spans, "one pulse of each, fired together");
}

/// Kills `head/overlap.rs` `GroupPlan::max`: `smear_mm >= 0.5 * circumference`
/// → `smear_mm >= 0.5 + circumference` (when the boxes are taken to wrap the
/// circle). Argued not to lower a figure (every box's arc centre lies within
/// a quarter circle of 0, so at a smear of half the circle every widened box
/// already holds one arc point: weight, counts and `spans` are the wrapped
/// ones), but it changes the worst position's arc: wrapped boxes have one left
/// end, −∞ (`GroupPlan`'s description), which `HeadFigures::worst_azimuth_deg`
/// reports.
///
/// By hand: one footprint at `ψ = 0`, half-arc 5 mm, on a circle of 100 mm,
/// one pulse in the window. At a smear of 49 mm the box is
/// `[−5 − 10⁻⁹, 5 + 49 + 10⁻⁹]`: the worst position's arc is its left end;
/// at 50 mm (half the circle, inclusive) and at 60 mm it wraps: −∞. The weight
/// is the one pulse's, 1, at every smear.
#[test]
fn a_smear_of_half_the_circle_wraps_the_group_s_boxes() {
    use gaze_lidar_core::eye_safety::head::geometry::Footprint;
    use gaze_lidar_core::eye_safety::head::overlap::{group, TOUCH_MM};
    let fp = Footprint {
        index: 0,
        psi_rad: 0.0,
        z_mm: 0.0,
        slant_mm: 100.0,
        width_mm: 3.0,
        cos_beta: 1.0,
        half_arc_mm: 5.0,
        half_height_mm: 5.0,
        pass_angle_deg: 0.1f64.to_degrees(),
    };
    let at = |smear_mm: f64| group(&[fp], &[1.0], &[0.0], 1e-3, 1e-4, smear_mm, 100.0);
    let (m, spans) = at(49.0);
    assert_eq!(
        (m.weight, m.count, m.arc_mm),
        (1.0, 1, -5.0 - TOUCH_MM),
        "{m:?}"
    );
    assert!(!spans);
    for smear_mm in [50.0, 60.0] {
        let (m, spans) = at(smear_mm);
        assert_eq!((m.weight, m.count), (1.0, 1), "{m:?}");
        assert_eq!(m.arc_mm, f64::NEG_INFINITY, "smear {smear_mm} mm: {m:?}");
        assert!(!spans);
    }
}
