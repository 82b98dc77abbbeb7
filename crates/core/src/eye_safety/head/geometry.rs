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
//! where the beam is `w_c = exit + divergence·d_c` wide.
//!
//! **The footprint.** A pulse counts (whole) at an aperture position when
//! the aperture (diameter `a`) and the beam overlap: the aperture centre is
//! within `ρ_c = (a + w_c)/2` of the ray, measured in the surface's tangent
//! plane at the hit point and laid along the surface (arc length and height:
//! the convention of the single-channel pass angle `(a + D)/R`, which is
//! exactly this for a radial ray). In that plane the set is an ellipse whose
//! bounding box has half-width `ρ_c / cos β_c` along the arc (`β_c` the
//! horizontal incidence, between the ray's horizontal direction and the
//! radial at the hit point) and half-height
//! `ρ_c·sqrt(1 + tan²ε_c / cos²β_c)`. The bound uses the box (it holds the
//! ellipse), so the pass of channel `c` is `(a + w_c)/(R·cos β_c)` rad.
//!
//! **Rounding.** The trigonometry is rounded outward by
//! [`GEOMETRY_MARGIN`] (relative) wherever it is not exact: a radial ray
//! (`r0 = 0` or `φ_c = 0`, `ε_c = 0`, no divergence) has `cos β = 1`,
//! `w = exit` exactly, so a 1-channel head of that shape has exactly the
//! single-channel pass angle.

use super::Head;

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
    /// Beam diameter there, mm.
    pub width_mm: f64,
    /// `cos β_c`, the horizontal incidence (rounded down).
    pub cos_beta: f64,
    /// Half-width of the footprint box along the arc, mm (aperture
    /// included).
    pub half_arc_mm: f64,
    /// Half-height of the footprint box, mm (aperture included).
    pub half_height_mm: f64,
    /// The head turn while the aperture is inside the box: the pass angle,
    /// deg, `((a + w)/(R·cos β)).to_degrees()` (not clamped).
    pub pass_angle_deg: f64,
}

/// The footprint of every channel of `head` for an aperture of `aperture_mm`.
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
                (head.exit_diameter_mm + head.divergence_mrad * slant * 1e-3)
                    * (1.0 + GEOMETRY_MARGIN)
            };
            // β = φ − ψ (angle between the ray and the radial at the hit).
            let radial = r0 == 0.0 || phi == 0.0;
            let cos_beta = if radial {
                1.0
            } else {
                ((phi - psi).cos() * (1.0 - GEOMETRY_MARGIN)).min(1.0)
            };
            let rho = 0.5 * (aperture_mm + width);
            let half_arc_mm = if radial {
                rho
            } else {
                rho / cos_beta * (1.0 + GEOMETRY_MARGIN)
            };
            let half_height_mm = if radial_flat {
                rho
            } else {
                let t = eps.tan() / cos_beta;
                rho * (1.0 + t * t).sqrt() * (1.0 + GEOMETRY_MARGIN)
            };
            let pass_angle_deg = if radial {
                ((aperture_mm + width) / r).to_degrees()
            } else {
                ((aperture_mm + width) / (r * cos_beta)).to_degrees() * (1.0 + GEOMETRY_MARGIN)
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
    /// d = s/cos10° = 44.1024 mm, w = 5 + 3·0.0441 = 5.1323 mm.
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
        assert!((f.width_mm - 5.1323).abs() < 1e-4);
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

    /// A radial flat ray without divergence: the single-channel pass angle,
    /// bit for bit.
    #[test]
    fn radial_ray_is_the_single_channel_pass() {
        let mut h = head(0.0, vec![ch(0, 0.0, 0.0)]);
        h.divergence_mrad = 0.0;
        let f = footprints(&h, 7.0)[0];
        assert_eq!(f.pass_angle_deg, ((7.0f64 + 5.0) / 100.0).to_degrees());
        assert_eq!(f.half_arc_mm, 6.0);
        assert_eq!(f.half_height_mm, 6.0);
        assert_eq!(f.width_mm, 5.0);
    }
}
