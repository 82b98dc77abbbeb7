//! Outside tester (break-sphere): the sphere footprint box against a brute-force
//! 3-D reach set on random heads (off-axis crossing points, steep and down-pointing
//! channels, wide beams near R − r0, large divergence, heights).
//!
//! Run: `cargo test --release -p gaze-lidar-core --test it -- break_sphere --nocapture`
//! (`BREAK_SPHERE_CASES=N`, default 20 in `cargo test`, about 0.17 s each; the tester ran 300 and 2,000). Measured: 300 cases, 0 failures, the farthest reached
//! position 0.9989 of the box's half-turn and 0.9997 of its half-height.

use gaze_lidar_core::eye_safety::head::geometry::{footprints_on, Surface};
use gaze_lidar_core::eye_safety::head::{Channel, Head};
use std::f64::consts::PI;

/// xorshift64*: deterministic.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64) / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

fn reach(r0: f64, el: f64, az: f64, exit: f64, div: f64, a: f64, p: [f64; 3]) -> bool {
    // p relative to the scan centre C; crossing point (r0, 0, 0).
    let (phi, eps) = (az.to_radians(), el.to_radians());
    let u = [eps.cos() * phi.cos(), eps.cos() * phi.sin(), eps.sin()];
    let d = [p[0] - r0, p[1], p[2]];
    let t = (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]).max(0.0);
    let e = [d[0] - t * u[0], d[1] - t * u[1], d[2] - t * u[2]];
    let rho = 0.5 * (a + exit + div * 1e-3 * t);
    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt() <= rho
}

#[test]
fn break_sphere_footprint_box_holds_every_reached_position() {
    let cases: usize = std::env::var("BREAK_SPHERE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut worst_arc = 0.0f64; // largest (reached |dθ|) / (box half-turn)
    let mut worst_h = 0.0f64;
    let mut fails = Vec::new();
    for case in 0..cases {
        let r0 = match case % 4 {
            0 => rng.range(0.0, 1.0),
            1 => rng.range(10.0, 90.0),
            2 => rng.range(85.0, 99.5),
            _ => rng.range(0.0, 99.0),
        };
        let el = match case % 3 {
            0 => rng.range(30.0, 89.5),
            1 => -rng.range(30.0, 89.5),
            _ => rng.range(-89.9, 89.9),
        };
        let az = rng.range(-89.9, 89.9);
        let rmax = 100.0 - r0;
        let exit = match case % 5 {
            0 => rng.range(0.1, 5.0),
            1 => (2.0 * rmax * rng.range(0.8, 0.999) - 7.0).max(0.1),
            2 => rng.range(5.0, 40.0),
            _ => rng.range(1.0, 15.0),
        };
        let div = match case % 7 {
            0 => rng.range(100.0, 1000.0),
            1 => rng.range(0.0, 20.0),
            _ => 0.0,
        };
        let z0 = rng.range(-50.0, 50.0);
        let a = 7.0;
        let head = Head {
            cycle_s: 1e-6,
            origin_radius_mm: r0,
            origin_height_mm: z0,
            exit_diameter_mm: exit,
            divergence_mrad: div,
            aperture_distance_mm: 100.0,
            channels: vec![Channel {
                id: 0,
                elevation_deg: el,
                azimuth_offset_deg: az,
                slot_s: 0.0,
                power_scale: 1.0,
            }],
        };
        if head.validate().is_err() {
            continue;
        }
        let f = footprints_on(&head, a, Surface::Sphere)[0];
        if f.pass_angle_deg >= 360.0 {
            continue;
        }
        let half = f.half_arc_mm / 100.0;
        let zc = f.z_mm - z0;
        // Samples: points of the sphere near the ray's hit, dense, plus a global grid.
        let (phi, eps) = (az.to_radians(), el.to_radians());
        let u = [eps.cos() * phi.cos(), eps.cos() * phi.sin(), eps.sin()];
        let mut check = |p: [f64; 3]| {
            if !reach(r0, el, az, exit, div, a, p) {
                return;
            }
            let th = p[1].atan2(p[0]);
            let mut dth = (th - f.psi_rad).rem_euclid(2.0 * PI);
            if dth > PI {
                dth -= 2.0 * PI;
            }
            let qa = dth.abs() / half;
            let qh = (p[2] - zc).abs() / f.half_height_mm;
            worst_arc = worst_arc.max(qa);
            worst_h = worst_h.max(qh);
            if qa > 1.0 || qh > 1.0 {
                fails.push((case, r0, el, az, exit, div, z0, qa, qh));
            }
        };
        // global grid in (Z, θ)
        let nz = 1200;
        let nt = 2400;
        for iz in 0..=nz {
            let z = -100.0 + 200.0 * iz as f64 / nz as f64;
            let rr = (1e4 - z * z).max(0.0).sqrt();
            for it in 0..nt {
                let th = 2.0 * PI * it as f64 / nt as f64;
                check([rr * th.cos(), rr * th.sin(), z]);
            }
        }
        // random points: project O + t u + v onto the sphere (from C), t and v random
        for _ in 0..400_000 {
            let t = rng.range(0.0, 250.0);
            let rho = 0.5 * (a + exit + div * 1e-3 * t) * 1.2;
            let v = [
                rng.range(-rho, rho),
                rng.range(-rho, rho),
                rng.range(-rho, rho),
            ];
            let q = [r0 + t * u[0] + v[0], t * u[1] + v[1], t * u[2] + v[2]];
            let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            if n < 1e-9 {
                continue;
            }
            check([100.0 * q[0] / n, 100.0 * q[1] / n, 100.0 * q[2] / n]);
        }
    }
    println!(
        "break_sphere: worst reached/box arc {worst_arc:.6}, height {worst_h:.6}; {} failures",
        fails.len()
    );
    for f in fails.iter().take(20) {
        println!("FAIL {f:?}");
    }
    assert!(fails.is_empty());
}
