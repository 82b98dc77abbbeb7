//! Step 1 of the head's argument: where each channel's beam meets the
//! aperture cylinder (radius `R` = `aperture_distance_mm` around the spin
//! axis) and the footprint there (`specs/eye_safety.md`, "The head").
//!
//! In the head frame (encoder azimuth 0 along +x, heights along the spin
//! axis) channel `c`'s ray leaves the crossing point `O = (r0, 0, z0)` with
//! horizontal direction at `φ_c` (its azimuth offset) from the radial +x and
//! elevation `ε_c`. It meets the cylinder at horizontal distance
//! `s_c = −r0·cos φ_c + sqrt(R² − r0²·sin²φ_c)`, at head-frame angle
//! `ψ_c = atan2(s_c·sin φ_c, r0 + s_c·cos φ_c)` and height
//! `z_c = z0 + s_c·tan ε_c`, after the slant distance `d_c = s_c / cos ε_c`,
//! where the beam is `w_c = exit + divergence·d_c` wide; the box takes
//! the widest beam over the footprint ([`widest_beam_mm`]: the aperture
//! centres a diverging ray reaches are nearest to points of it up to
//! `R + ρ` from the axis, farther out than the hit).
//!
//! **The footprint.** A pulse counts (whole) at an aperture position when
//! the aperture (diameter `a`) and the beam overlap. Whatever way the
//! aperture faces, that needs its centre within `ρ_c = (a + w_c)/2` of the
//! ray in 3-D (the aperture facing the beam is the case where the set is
//! largest: a tilted aperture's disc, seen along the beam, lies inside the
//! facing one's). With `α = φ_c − θ` (`θ` the aperture centre's head-frame
//! angle), the centre's horizontal distance to the ray's horizontal line is
//! `|R·sin α − r0·sin φ_c|`, and along it `a(α) = R·cos α − r0·cos φ_c`;
//! in 3-D the distance is `sqrt(b² + (a·sin ε − Z·cos ε)²)` (`b` the
//! horizontal one, `Z` the height above the crossing point) while the
//! centre is ahead of the crossing point. So, with `s = r0·sin φ_c / R`
//! (`= sin β_c`, `β_c = φ_c − ψ_c` the horizontal incidence) and
//! `q = ρ_c/R`, the set lies in `α ∈ [asin(s − q), asin(s + q)]` (each end
//! clamped to ±90°: beyond it the centre is behind the crossing point,
//! at least `R − r0 > ρ_c` from it) and, at each `α`, in heights
//! `Z ∈ a(α)·tan ε ± ρ_c/cos ε`. The bound uses the box centred on the hit
//! point that holds that set: half-turn `h_c = max(asin(s+q) − β_c,
//! β_c − asin(s−q))`, half-height `ρ_c/cos ε + |tan ε|·max|a(α) − s_c|`. A
//! radial ray (`s = 0`) has the single-channel pass angle `2·asin(ρ/R)`
//! ([`radial_pass_angle_deg`]). When `R − r0 ≤ ρ_c` the crossing point
//! itself is within reach: the box is the whole turn and every height the
//! ray and the ball around the crossing point can reach.
//!
//! **Rounding.** The trigonometry is rounded outward by
//! [`GEOMETRY_MARGIN`] (relative) wherever it is not exact: a flat ray
//! without divergence has `w = exit` exactly and half-height `ρ` exactly; a
//! radial ray has exactly the single-channel pass angle (both are
//! [`radial_pass_angle_deg`]).

use super::Head;

pub mod sphere;

/// Relative widening of every footprint size that comes from rounded
/// trigonometry (a few ulps of error, 1e-12 ≫ 10·2⁻⁵²).
pub const GEOMETRY_MARGIN: f64 = 1e-12;

/// One channel's beam at the aperture cylinder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Index of the channel in the head's list.
    pub index: usize,
    /// Head-frame angle of the hit point, rad.
    pub psi_rad: f64,
    /// Height of the hit point, mm.
    pub z_mm: f64,
    /// Slant distance from the crossing point, mm.
    pub slant_mm: f64,
    /// Beam diameter the box is drawn with, mm: the widest over the
    /// footprint (no reached position's nearest point sees a wider beam).
    pub width_mm: f64,
    /// `cos β_c`, the horizontal incidence (rounded down; reported, the
    /// box does not use it).
    pub cos_beta: f64,
    /// Half-width of the footprint box along the arc, mm (aperture
    /// included).
    pub half_arc_mm: f64,
    /// Half-height of the footprint box, mm (aperture included).
    pub half_height_mm: f64,
    /// The head turn while the aperture is inside the box: the pass angle,
    /// deg, `2·h_c` (360 when the box is the whole turn).
    pub pass_angle_deg: f64,
}

/// The head turn, deg, while the Condition 3 aperture (diameter
/// `aperture_mm`) `r_mm` from the spin axis overlaps a beam `width_mm` wide
/// on a ray leaving the axis: its centre within `ρ = (a + w)/2` of the ray
/// in 3-D, `2·asin(ρ/R)`, rounded up by [`GEOMETRY_MARGIN`]; 360 once
/// `ρ ≥ R` (the beam reaches the aperture at every turn). The one pass
/// angle of the single-channel bound and of a radial channel of a head.
#[must_use]
pub fn radial_pass_angle_deg(aperture_mm: f64, width_mm: f64, r_mm: f64) -> f64 {
    let q = 0.5 * (aperture_mm + width_mm) / r_mm;
    if q >= 1.0 {
        360.0
    } else {
        (2.0 * q.asin()).to_degrees() * (1.0 + GEOMETRY_MARGIN)
    }
}

/// The box holding the aperture positions (head-frame angle, height) at
/// which a ray meets the aperture: half-turn (rad) and half-height (mm)
/// around the hit point. `s = r0·sin φ/R`, `q = ρ/R`, `s_c` the horizontal
/// distance to the hit point, `cos_phi_r0 = r0·cos φ`, `eps` the elevation
/// (module docs).
fn footprint_box(
    r: f64,
    s: f64,
    q: f64,
    s_c: f64,
    cos_phi_r0: f64,
    eps: f64,
    rho: f64,
) -> (f64, f64) {
    let lo = (s - q).max(-1.0).asin();
    let hi = (s + q).min(1.0).asin();
    let beta = s.asin();
    let half_turn = (hi - beta).max(beta - lo);
    if eps == 0.0 {
        return (half_turn, rho);
    }
    let a = |alpha: f64| r * alpha.cos() - cos_phi_r0;
    let a_max = if lo <= 0.0 && 0.0 <= hi {
        r - cos_phi_r0
    } else {
        a(lo).max(a(hi))
    };
    let a_min = a(lo).min(a(hi));
    let spread = (a_max - s_c).max(s_c - a_min).max(0.0);
    (half_turn, rho / eps.cos() + eps.tan().abs() * spread)
}

/// The aperture positions a head evaluation covers (`specs/eye_safety.md`,
/// "The aperture's surface"): both are `R` = `aperture_distance_mm` from a
/// reference, and a certificate covers both at 100 mm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Surface {
    /// Every position `R` from the spin axis (the module docs).
    Cylinder,
    /// Every position `R` from the scan centre, the point of the spin axis
    /// at the crossing point's height ([`sphere`]).
    Sphere,
}

impl Surface {
    /// Both surfaces, the cylinder first.
    pub const ALL: [Surface; 2] = [Surface::Cylinder, Surface::Sphere];

    /// Whether this is the cylinder (serialization skips it).
    #[must_use]
    pub fn is_cylinder(&self) -> bool {
        *self == Surface::Cylinder
    }

    /// The surface's name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Surface::Cylinder => "cylinder",
            Surface::Sphere => "sphere",
        }
    }
}

/// The footprint of every channel of `head` for an aperture of `aperture_mm`
/// on `surface`.
#[must_use]
pub fn footprints_on(head: &Head, aperture_mm: f64, surface: Surface) -> Vec<Footprint> {
    match surface {
        Surface::Cylinder => footprints(head, aperture_mm),
        Surface::Sphere => sphere::footprints(head, aperture_mm),
    }
}

/// The widest beam, mm, at any point of a diverging ray nearest an aperture
/// centre it reaches on the cylinder (`r0·cos φ`, `r0·sin φ`, `cos ε`
/// given): such a point `Q` is within `ρ` of the centre, so at most `R + ρ`
/// from the axis, at slant `t ≤ t(ρ) = (−r0·cos φ + sqrt((R + ρ)² −
/// r0²·sin²φ))/cos ε`; `ρ = (a + w(t))/2` with `t(ρ) ≤ (r0 + R + ρ)/cos ε`
/// bounds `ρ` by `ρ₁ = (a + e + k·(r0 + R)/cos ε)/(2 − k/cos ε)` (`k` the
/// divergence, `e` the exit), and the beam at `t(ρ₁)` holds every reached
/// centre's (`t(ρ)` grows with `ρ`). Rounded up by [`GEOMETRY_MARGIN`]. A
/// beam diverging by at least `cos ε` rad (`k ≥ cos ε`, far outside any
/// real head; at `k ≥ 2·cos ε` its reach up the cylinder has no bound) is
/// taken as infinitely wide: its box is the whole cylinder, every turn and
/// every height. (It was once a kilometre wide, and a beam 75° up diverging
/// by 1 rad reaches heights where it is wider than that: the brute force
/// below found one at 1,004,769 mm.)
fn widest_beam_mm(
    head: &Head,
    aperture_mm: f64,
    r0_cos_phi: f64,
    r0_sin_phi: f64,
    cos_eps: f64,
) -> f64 {
    let r = head.aperture_distance_mm;
    let k = head.divergence_mrad * 1e-3;
    let kc = k / cos_eps;
    if kc >= 1.0 || kc.is_nan() {
        return f64::INFINITY;
    }
    let r0 = r0_cos_phi.hypot(r0_sin_phi);
    let rho1 = 0.5 * (aperture_mm + head.exit_diameter_mm + kc * (r0 + r)) / (1.0 - 0.5 * kc);
    let reach = r + rho1;
    let t = (-r0_cos_phi + (reach * reach - r0_sin_phi * r0_sin_phi).max(0.0).sqrt()) / cos_eps;
    (head.exit_diameter_mm + head.divergence_mrad * t * 1e-3) * (1.0 + GEOMETRY_MARGIN)
}

/// The footprint of every channel of `head` for an aperture of `aperture_mm`
/// on the cylinder.
#[must_use]
pub fn footprints(head: &Head, aperture_mm: f64) -> Vec<Footprint> {
    let r = head.aperture_distance_mm;
    let r0 = head.origin_radius_mm;
    head.channels
        .iter()
        .enumerate()
        .map(|(index, c)| {
            let phi = c.azimuth_offset_deg.to_radians();
            let eps = c.elevation_deg.to_radians();
            let (sp, cp) = phi.sin_cos();
            let s = -r0 * cp + (r * r - r0 * r0 * sp * sp).sqrt();
            let psi = (s * sp).atan2(r0 + s * cp);
            let z = head.origin_height_mm + s * eps.tan();
            let radial_flat = c.elevation_deg == 0.0;
            let slant = if radial_flat { s } else { s / eps.cos() };
            let width = if head.divergence_mrad == 0.0 {
                head.exit_diameter_mm
            } else {
                widest_beam_mm(head, aperture_mm, r0 * cp, r0 * sp, eps.cos())
            };
            // β = φ − ψ (angle between the ray and the radial at the hit).
            let radial = r0 == 0.0 || phi == 0.0;
            let cos_beta = if radial {
                1.0
            } else {
                ((phi - psi).cos() * (1.0 - GEOMETRY_MARGIN)).min(1.0)
            };
            let rho = 0.5 * (aperture_mm + width);
            let (pass_angle_deg, half_arc_mm, half_height_mm) = if r - r0 <= rho {
                // The crossing point is within reach: every turn, and every
                // height the ray (|a| ≤ R + r0 along it) or the ball of
                // radius ρ around the crossing point reaches.
                let spread = r + r0 + s.abs();
                let hh = rho / eps.cos() + eps.tan().abs() * spread + rho;
                (
                    360.0,
                    r * std::f64::consts::PI,
                    hh * (1.0 + GEOMETRY_MARGIN),
                )
            } else {
                let (h, hh) = footprint_box(r, r0 * sp / r, rho / r, s, r0 * cp, eps, rho);
                let pass = if radial {
                    radial_pass_angle_deg(aperture_mm, width, r)
                } else {
                    (2.0 * h).to_degrees() * (1.0 + GEOMETRY_MARGIN)
                };
                let hh = if radial_flat {
                    hh
                } else {
                    hh * (1.0 + GEOMETRY_MARGIN)
                };
                (
                    pass,
                    0.5 * pass.to_radians() * r * (1.0 + GEOMETRY_MARGIN),
                    hh,
                )
            };
            Footprint {
                index,
                psi_rad: psi,
                z_mm: z,
                slant_mm: slant,
                width_mm: width,
                cos_beta,
                half_arc_mm,
                half_height_mm,
                pass_angle_deg,
            }
        })
        .collect()
}

/// Aperture positions `(θ, Z)` to probe a footprint's box with: a coarse
/// grid over the whole turn and `z_range` (3601 × 401), and a fine one
/// over 1.5 times the box (1201 × 1201), where a short box shows.
#[cfg(test)]
pub(crate) fn probe_positions(f: &Footprint, z_range: (f64, f64)) -> Vec<(f64, f64)> {
    use core::f64::consts::PI;
    let mut out = Vec::with_capacity(3601 * 401 + 1201 * 1201);
    for i in 0..=3600 {
        let theta = f.psi_rad + (f64::from(i) / 1800.0 - 1.0) * PI;
        for k in 0..=400 {
            out.push((
                theta,
                z_range.0 + (z_range.1 - z_range.0) * f64::from(k) / 400.0,
            ));
        }
    }
    let half_turn = (0.5 * f.pass_angle_deg.to_radians()).min(PI / 1.5);
    for i in 0..=1200 {
        let theta = f.psi_rad + 1.5 * half_turn * (f64::from(i) / 600.0 - 1.0);
        for k in 0..=1200 {
            out.push((
                theta,
                f.z_mm + 1.5 * f.half_height_mm * (f64::from(k) / 600.0 - 1.0),
            ));
        }
    }
    out
}

/// When an aperture centre `p` (mm, the crossing point's height at 0) is
/// within `(a + w)/2` of the ray from `(r0, 0, 0)` along `u` (3-D distance
/// to the half-line, the beam `w = exit + divergence·t` at the nearest
/// point `t`, a = 7 mm), the beam's width `w` there; `None` when out of
/// reach. The reach the brute-force tests hold boxes (and their
/// `width_mm`) to.
#[cfg(test)]
pub(crate) fn reached_at(
    p: [f64; 3],
    r0: f64,
    u: [f64; 3],
    exit_mm: f64,
    divergence_mrad: f64,
) -> Option<f64> {
    let d = [p[0] - r0, p[1], p[2]];
    let t = (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]).max(0.0);
    let e = [d[0] - t * u[0], d[1] - t * u[1], d[2] - t * u[2]];
    let width = exit_mm + divergence_mrad * 1e-3 * t;
    ((e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt() <= 0.5 * (7.0 + width)).then_some(width)
}

/// Points of the edge of the reached set on the surface (`sphere`: the
/// 100 mm sphere around the axis point at the crossing point's height, else
/// the 100 mm cylinder): for `n` directions `v̂` about the ray (the crossing
/// point `(r0, 0, 0)`, direction `u`), the points `O + t·u + ρ(t)·v̂` on the
/// surface, `ρ(t) = (a + exit + divergence·t)/2` (a = 7 mm) shrunk by 1e-9
/// so that [`reached_at`] reaches them. The reached set is the surface
/// inside the beam's tube; the angle and the height have no extremum inside
/// it but at a pole (which the caller probes), so its extent is that of
/// these edge points: the brute force of the boxes over random rays.
#[cfg(test)]
pub(crate) fn reach_edge(
    r0: f64,
    u: [f64; 3],
    exit_mm: f64,
    divergence_mrad: f64,
    sphere: bool,
    n: usize,
) -> Vec<[f64; 3]> {
    let h = u[0].hypot(u[1]);
    // e1 horizontal and across the ray, e2 = u × e1.
    let e1 = if h > 0.0 {
        [-u[1] / h, u[0] / h, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e2 = [
        u[1] * e1[2] - u[2] * e1[1],
        u[2] * e1[0] - u[0] * e1[2],
        u[0] * e1[1] - u[1] * e1[0],
    ];
    let shrink = 1.0 - 1e-9;
    let rho0 = 0.5 * (7.0 + exit_mm) * shrink;
    let kh = 0.5 * divergence_mrad * 1e-3 * shrink;
    let mut out = Vec::new();
    for i in 0..n {
        let (sa, ca) = (core::f64::consts::TAU * i as f64 / n as f64).sin_cos();
        let v = [
            ca * e1[0] + sa * e2[0],
            ca * e1[1] + sa * e2[1],
            ca * e1[2] + sa * e2[2],
        ];
        let a = [r0 + rho0 * v[0], rho0 * v[1], rho0 * v[2]];
        let b = [u[0] + kh * v[0], u[1] + kh * v[1], u[2] + kh * v[2]];
        // |a + t·b|² = R² (on the cylinder, of the horizontal part).
        let m = if sphere { 1.0 } else { 0.0 };
        let qa = b[0] * b[0] + b[1] * b[1] + m * b[2] * b[2];
        let qb = 2.0 * (a[0] * b[0] + a[1] * b[1] + m * a[2] * b[2]);
        let qc = a[0] * a[0] + a[1] * a[1] + m * a[2] * a[2] - 1e4;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa <= 0.0 || disc < 0.0 {
            continue;
        }
        for t in [
            (-qb - disc.sqrt()) / (2.0 * qa),
            (-qb + disc.sqrt()) / (2.0 * qa),
        ] {
            if t >= 0.0 {
                out.push([a[0] + t * b[0], a[1] + t * b[1], a[2] + t * b[2]]);
            }
        }
    }
    // Behind the crossing point the reach is the ball of radius ρ(0)
    // around it: its edge on the surface, where it is behind.
    let behind = |p: [f64; 3]| (p[0] - r0) * u[0] + p[1] * u[1] + p[2] * u[2] <= 0.0;
    for i in 0..n {
        let w = -1.0 + 2.0 * i as f64 / (n - 1).max(1) as f64;
        if sphere {
            // Heights over the sphere: cos θ from |P − O| = ρ(0).
            let z = 100.0 * w;
            let rz = (1e4 - z * z).max(0.0).sqrt();
            let c = (1e4 + r0 * r0 - rho0 * rho0) / (2.0 * r0 * rz);
            if c.abs() <= 1.0 {
                let th = c.acos();
                for th in [th, -th] {
                    let p = [rz * th.cos(), rz * th.sin(), z];
                    if behind(p) {
                        out.push(p);
                    }
                }
            }
        } else {
            // Angles round the cylinder: the height from |P − O| = ρ(0).
            let th = core::f64::consts::PI * w;
            let (x, y) = (100.0 * th.cos(), 100.0 * th.sin());
            let z2 = rho0 * rho0 - (x - r0) * (x - r0) - y * y;
            if z2 >= 0.0 {
                for z in [z2.sqrt(), -z2.sqrt()] {
                    let p = [x, y, z];
                    if behind(p) {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}

/// Why the surface point `p` (reached, with a beam `width_mm` wide) lies
/// outside `f`'s box (`z_hit` the hit's height in `p`'s frame), or `None`.
#[cfg(test)]
pub(crate) fn outside_box(f: &Footprint, p: [f64; 3], width_mm: f64, z_hit: f64) -> Option<String> {
    use core::f64::consts::{PI, TAU};
    let mut dth = (p[1].atan2(p[0]) - f.psi_rad).rem_euclid(TAU);
    if dth > PI {
        dth -= TAU;
    }
    if width_mm > f.width_mm {
        Some(format!("beam {width_mm} > {}", f.width_mm))
    } else if dth.abs() * 100.0 > f.half_arc_mm {
        Some(format!("arc {} > {}", dth.abs() * 100.0, f.half_arc_mm))
    } else if dth.abs().to_degrees() > 0.5 * f.pass_angle_deg {
        Some(format!(
            "angle {} > half the pass {}",
            dth.abs().to_degrees(),
            0.5 * f.pass_angle_deg
        ))
    } else if (p[2] - z_hit).abs() > f.half_height_mm {
        Some(format!(
            "height {} > {}",
            (p[2] - z_hit).abs(),
            f.half_height_mm
        ))
    } else {
        None
    }
}

/// The first edge point of one channel's reached set (elevation `el`,
/// azimuth offset `az`, degrees) outside its box on `surface`, and why; a
/// reached pole must have the whole turn; `None` when the box holds them
/// all.
#[cfg(test)]
pub(crate) fn edge_outside_box(
    surface: Surface,
    r0: f64,
    el: f64,
    az: f64,
    exit_mm: f64,
    divergence_mrad: f64,
) -> Option<String> {
    let head = Head {
        cycle_s: 1e-4,
        origin_radius_mm: r0,
        origin_height_mm: 0.0,
        exit_diameter_mm: exit_mm,
        divergence_mrad,
        aperture_distance_mm: 100.0,
        channels: vec![crate::eye_safety::head::Channel {
            id: 0,
            elevation_deg: el,
            azimuth_offset_deg: az,
            slot_s: 0.0,
            power_scale: 1.0,
        }],
    };
    let f = footprints_on(&head, 7.0, surface)[0];
    let (phi, eps) = (az.to_radians(), el.to_radians());
    let u = [eps.cos() * phi.cos(), eps.cos() * phi.sin(), eps.sin()];
    let sphere = surface == Surface::Sphere;
    for p in reach_edge(r0, u, exit_mm, divergence_mrad, sphere, 1024) {
        let Some(width) = reached_at(p, r0, u, exit_mm, divergence_mrad) else {
            return Some(format!("the edge point {p:?} is not reached"));
        };
        if let Some(why) = outside_box(&f, p, width, f.z_mm) {
            return Some(format!("{p:?}: {why}"));
        }
    }
    // A coarse grid over the surface (a set with no edge covers all of it).
    for i in 0..72 {
        let th = core::f64::consts::TAU * f64::from(i) / 72.0;
        for k in 0..=40 {
            let z = -100.0 + 5.0 * f64::from(k);
            let r = if sphere {
                (1e4 - z * z).max(0.0).sqrt()
            } else {
                100.0
            };
            let p = [r * th.cos(), r * th.sin(), z];
            if let Some(width) = reached_at(p, r0, u, exit_mm, divergence_mrad) {
                if let Some(why) = outside_box(&f, p, width, f.z_mm) {
                    return Some(format!("{p:?} (grid): {why}"));
                }
            }
        }
    }
    for z in [100.0, -100.0] {
        let pole = [0.0, 0.0, z];
        if sphere && reached_at(pole, r0, u, exit_mm, divergence_mrad).is_some() {
            let whole = f.pass_angle_deg >= 360.0 && f.half_arc_mm >= 100.0 * core::f64::consts::PI;
            if !whole || (z - f.z_mm).abs() > f.half_height_mm {
                return Some(format!(
                    "the pole {z} is reached, the box is not the whole turn to it"
                ));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_safety::head::{Channel, Head};

    fn head(r0: f64, channels: Vec<Channel>) -> Head {
        Head {
            cycle_s: 1e-4,
            origin_radius_mm: r0,
            origin_height_mm: 0.0,
            exit_diameter_mm: 5.0,
            divergence_mrad: 3.0,
            aperture_distance_mm: 100.0,
            channels,
        }
    }

    fn ch(id: u32, el: f64, az: f64) -> Channel {
        Channel {
            id,
            elevation_deg: el,
            azimuth_offset_deg: az,
            slot_s: 0.0,
            power_scale: 1.0,
        }
    }

    /// By hand: r0 = 60, φ = 30°, R = 100: s = −60·cos30° + sqrt(10⁴ −
    /// 3600·0.25) = −51.9615 + 95.3939 = 43.4324 mm; the hit point
    /// (60 + 37.6136, 21.7162) is at ψ = atan2(21.7162, 97.6136) = 12.543°;
    /// β = 30° − 12.543° = 17.457°. With ε = 10°: z = s·tan10° = 7.6583,
    /// d = s/cos10° = 44.1024 mm (the beam there 5 + 3·0.0441 = 5.1323
    /// mm). The widest beam over the footprint: `ρ₁ = 0.5·(7 + 5 +
    /// 0.0030463·160)/(1 − 0.0015231)` = 6.2532 mm, the nearest points of
    /// the ray out to `R + ρ₁` = 106.2532 mm from the axis, at slant
    /// `(−51.9615 + sqrt(106.2532² − 30²))/cos10°` = 50.7394 mm:
    /// w = 5 + 3·0.0507394 = 5.1522 mm.
    #[test]
    fn oblique_ray_by_hand() {
        let h = head(60.0, vec![ch(0, 10.0, 30.0)]);
        let f = footprints(&h, 7.0)[0];
        let s = -60.0 * 30f64.to_radians().cos() + (1e4f64 - 3600.0 * 0.25).sqrt();
        assert!((s - 43.4324).abs() < 1e-4, "{s}");
        assert!(
            (f.psi_rad.to_degrees() - 12.543).abs() < 1e-3,
            "{}",
            f.psi_rad.to_degrees()
        );
        assert!((f.z_mm - 7.6583).abs() < 1e-4, "{}", f.z_mm);
        assert!((f.slant_mm - 44.1024).abs() < 1e-4);
        assert!((f.width_mm - 5.1522).abs() < 1e-4, "{}", f.width_mm);
        let beta = (30.0 - 12.543f64).to_radians();
        assert!((f.cos_beta - beta.cos()).abs() < 1e-4);
        // The hit point is on the cylinder.
        let (x, y) = (
            60.0 + s * 30f64.to_radians().cos(),
            s * 30f64.to_radians().sin(),
        );
        assert!(((x * x + y * y).sqrt() - 100.0).abs() < 1e-9);
        assert!(f.half_arc_mm > 0.5 * (7.0 + f.width_mm) / beta.cos());
    }

    /// The surfaces' names, as reports and JSON spell them, and the one
    /// serialization leaves out (the cylinder: a report without a surface
    /// is the cylinder's).
    #[test]
    fn surfaces_are_named_and_only_the_cylinder_is_left_out() {
        assert_eq!(Surface::Cylinder.name(), "cylinder");
        assert_eq!(Surface::Sphere.name(), "sphere");
        assert!(Surface::Cylinder.is_cylinder());
        assert!(!Surface::Sphere.is_cylinder());
        for s in Surface::ALL {
            assert_eq!(
                serde_json::to_string(&s).unwrap(),
                format!("\"{}\"", s.name())
            );
        }
    }

    /// A radial flat ray without divergence: the single-channel pass angle,
    /// bit for bit; by hand `2·asin(6/100)` = 6.8797°, the arc's half-width
    /// `100·asin(0.06)` = 6.0036 mm (the chord laid as an arc, 6.8755° and
    /// 6 mm, was short), half-height `ρ` = 6 mm exactly.
    #[test]
    fn radial_ray_is_the_single_channel_pass() {
        let mut h = head(0.0, vec![ch(0, 0.0, 0.0)]);
        h.divergence_mrad = 0.0;
        let f = footprints(&h, 7.0)[0];
        let single = crate::eye_safety::exposure::scan_pass_angle_deg(
            crate::eye_safety::ael::Band::of(905.0).unwrap(),
            5.0,
        );
        assert_eq!(f.pass_angle_deg.to_bits(), single.to_bits());
        assert!(
            (f.pass_angle_deg - 6.8797).abs() < 1e-4,
            "{}",
            f.pass_angle_deg
        );
        assert!(f.pass_angle_deg > ((7.0f64 + 5.0) / 100.0).to_degrees());
        assert!((f.half_arc_mm - 6.0036).abs() < 1e-4, "{}", f.half_arc_mm);
        assert_eq!(f.half_height_mm, 6.0);
        assert_eq!(f.width_mm, 5.0);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(
            std::env::var("GAZE_LIDAR_EDGE_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(4096)
        ))]
        /// Random rays over the whole input space (crossing points from the
        /// axis to 0.1 mm inside the surface, every elevation short of the
        /// vertical and offset, beams from 10 µm to 600 mm, divergences to
        /// the validated 1000 mrad): every point of the reached set's edge
        /// ([`reach_edge`], 1024 directions about the ray) lies in the
        /// channel's box on both surfaces, and a reached pole makes the
        /// sphere's box the whole turn.
        #[test]
        fn random_rays_stay_in_their_boxes_on_both_surfaces(
            r0 in proptest::prop_oneof![0.0f64..99.9, 90.0f64..99.9, proptest::strategy::Just(0.0)],
            el in proptest::prop_oneof![-89.5f64..89.5, 60.0f64..89.5, -89.5f64..-60.0],
            az in -180.0f64..180.0,
            exit in proptest::prop_oneof![0.01f64..15.0, 0.01f64..600.0],
            div in proptest::prop_oneof![proptest::strategy::Just(0.0), 0.0f64..20.0, 0.0f64..999.0],
        ) {
            for surface in Surface::ALL {
                let why = edge_outside_box(surface, r0, el, az, exit, div);
                proptest::prop_assert!(
                    why.is_none(),
                    "{} r0 {r0} el {el} az {az} exit {exit} div {div}: {}",
                    surface.name(),
                    why.unwrap_or_default()
                );
            }
        }
    }

    /// The 3-D reading by brute force: on a grid of aperture centres on the
    /// cylinder, every one within `(a + w(t))/2` of the ray (3-D distance to
    /// the half-line, `w` the beam at the nearest point) lies in the
    /// footprint box, for oblique, steep, grazing (`r0` = 90 mm at 80°,
    /// `s + q > 1`) and strongly diverging rays (with the beam taken at the
    /// hit alone, the box of the 200 mrad ray 60° up is short: a centre
    /// 58.000 mm above the hit is reached, the box held 57.957 mm); steep
    /// oblique rays with wide and thin beams, where the ray's run between
    /// the hit and the nearest points (`spread` in [`footprint_box`]) sets
    /// much of the height; and crossing points within reach of the
    /// surface (`r0` 95–99.5 mm: every turn), among them a ray grazing the
    /// cylinder from 0.5 mm inside it, which is reached 46 mm from its hit
    /// height (the `R + r0` of the whole-turn height is needed there:
    /// `R − r0` leaves the box 10 mm short), and very wide beams steep up
    /// from within reach (a 600 mm beam 80° up from the axis is reached
    /// `ρ/cos ε` = 1,744 mm above its hit height: `ρ·cos ε` there leaves
    /// the box at 1,490).
    #[test]
    fn the_box_holds_every_position_within_reach_of_the_ray() {
        // r0, elevation, offset, exit, divergence, and the least share of
        // the box's half-arc and half-height some reached position must fill
        // (on the probe grid, less 0.02): the box is not loose beyond that.
        let cases = [
            (60.0, 10.0, 30.0, 5.0, 3.0, 0.97, 0.92),
            // Grazing: the box holds the whole chord the ray can cut.
            (90.0, 0.0, 80.0, 20.0, 0.0, 0.1, 0.45),
            (40.0, 25.0, -20.0, 10.0, 1.0, 0.97, 0.9),
            (0.0, 30.0, 0.0, 150.0, 0.0, 0.97, 0.78),
            (58.63, -25.0, 5.0, 10.0, 2.0, 0.97, 0.93),
            (20.0, 15.0, -10.0, 5.0, 200.0, 0.83, 0.84),
            (50.0, -40.0, 30.0, 2.0, 100.0, 0.85, 0.76),
            (0.0, 60.0, 0.0, 5.0, 200.0, 0.76, 0.82),
            (58.0, 0.0, 90.0, 0.1, 10.0, 0.96, 0.97),
            (58.0, 10.0, 60.0, 0.2, 5.0, 0.97, 0.88),
            // Divergence at or past twice cos ε (no finite reach: the whole
            // cylinder), and a thin exit under it.
            (20.0, 75.0, 0.0, 2.0, 1000.0, 0.0, 0.0),
            (20.0, 70.0, 30.0, 1e-4, 800.0, 0.0, 0.0),
            (60.0, 60.0, 60.0, 1.0, 0.0, 0.97, 0.71),
            (80.0, 45.0, 45.0, 1.0, 0.5, 0.97, 0.71),
            (70.0, -50.0, -75.0, 0.5, 0.0, 0.97, 0.68),
            (95.0, 30.0, 180.0, 5.0, 0.0, 0.98, 0.46),
            (95.0, 40.0, 90.0, 5.0, 0.0, 0.09, 0.12),
            (97.0, -20.0, 20.0, 6.0, 0.0, 0.01, 0.06),
            (95.0, 10.0, 0.0, 5.0, 0.0, 0.01, 0.1),
            (99.5, 60.0, 90.0, 5.0, 0.0, 0.06, 0.1),
            (60.0, 60.0, 60.0, 30.0, 0.0, 0.97, 0.67),
            (30.0, 50.0, 45.0, 25.0, 0.0, 0.97, 0.8),
            (30.0, 60.0, 10.0, 0.1, 0.0, 0.97, 0.92),
            (96.0, 70.0, 180.0, 5.0, 0.0, 0.98, 0.47),
            (99.5, 75.0, 90.0, 5.0, 0.0, 0.06, 0.1),
            (0.0, 80.0, 0.0, 600.0, 0.0, 0.98, 0.53),
            (30.0, 70.0, 45.0, 400.0, 0.0, 0.98, 0.42),
        ];
        for (r0, el, az, exit, div, arc_min, height_min) in cases {
            let mut h = head(r0, vec![ch(0, el, az)]);
            h.exit_diameter_mm = exit;
            h.divergence_mrad = div;
            let f = footprints(&h, 7.0)[0];
            let (phi, eps) = (f64::to_radians(az), f64::to_radians(el));
            let u = [eps.cos() * phi.cos(), eps.cos() * phi.sin(), eps.sin()];
            let mut inside = 0;
            let (mut arc, mut height) = (0.0f64, 0.0f64);
            let span = 4.0 * (f.width_mm.min(1e3) + 100.0);
            for (theta, z) in probe_positions(&f, (f.z_mm - span, f.z_mm + span)) {
                {
                    let Some(width) = reached_at(
                        [100.0 * theta.cos(), 100.0 * theta.sin(), z],
                        r0,
                        u,
                        exit,
                        div,
                    ) else {
                        continue;
                    };
                    inside += 1;
                    assert!(
                        width <= f.width_mm,
                        "{r0} {el} {az}: beam {width} > {}",
                        f.width_mm
                    );
                    let mut dth = (theta - f.psi_rad).rem_euclid(std::f64::consts::TAU);
                    if dth > std::f64::consts::PI {
                        dth -= std::f64::consts::TAU;
                    }
                    assert!(
                        dth.abs() * 100.0 <= f.half_arc_mm,
                        "{r0} {el} {az}: arc {} > {}",
                        dth.abs() * 100.0,
                        f.half_arc_mm
                    );
                    assert!(dth.abs().to_degrees() <= 0.5 * f.pass_angle_deg);
                    assert!(
                        (z - f.z_mm).abs() <= f.half_height_mm,
                        "{r0} {el} {az}: height {} > {}",
                        (z - f.z_mm).abs(),
                        f.half_height_mm
                    );
                    arc = arc.max(dth.abs() * 100.0 / f.half_arc_mm);
                    height = height.max((z - f.z_mm).abs() / f.half_height_mm);
                }
            }
            assert!(inside > 10, "{r0} {el} {az}: {inside}");
            println!(
                "{r0} {el} {az}: reached {arc:.4} of the half-arc, {height:.4} of the half-height, width {:.4} mm",
                f.width_mm
            );
            assert!(
                arc >= arc_min && height >= height_min,
                "{r0} {el} {az}: loose box"
            );
            if arc_min == 0.0 && f.width_mm.is_infinite() {
                assert!(f.width_mm.is_infinite() && f.half_height_mm.is_infinite());
                assert_eq!(f.pass_angle_deg, 360.0);
            }
        }
    }
}
