//! 3D geometry of the `carla` sensor: a multi-channel spinning LiDAR on a
//! mount above a flat road, buildings as axis-aligned boxes and vehicles as
//! posed boxes (nalgebra points, vectors and isometries), and the exact ray
//! casts (slab test; ground plane `z = 0`).
//!
//! Frames: the *road frame* is ISO 8855 on the ground (x forward, y left,
//! z up, z = 0 the road surface, origin below the LiDAR); the *sensor frame*
//! is the road frame moved up by the mount height (ARGUS's point frame after
//! its x flip of CARLA's yaw-180° mount: x forward, y left, z up).

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The elevation angles of CARLA's `sensor.lidar.ray_cast`: channel `i` of
/// `n` points `upper − i·(upper − lower)/(n − 1)` degrees above the
/// horizon (`CreateLasers`; one channel: `upper`).
#[must_use]
pub fn carla_elevations_deg(channels: u32, upper_deg: f64, lower_deg: f64) -> Vec<f64> {
    let step = if channels <= 1 {
        0.0
    } else {
        (upper_deg - lower_deg) / f64::from(channels - 1)
    };
    (0..channels)
        .map(|i| upper_deg - f64::from(i) * step)
        .collect()
}

/// The LiDAR: its mount and its channels.
#[derive(Debug, Clone)]
pub struct Sensor {
    /// Pose of the sensor frame in the road frame.
    pub mount: Isometry3<f64>,
    /// Elevation of each channel, degrees.
    pub elevations_deg: Vec<f64>,
    /// `cos` of each channel's elevation.
    pub cos_el: Vec<f64>,
    /// `sin` of each channel's elevation.
    pub sin_el: Vec<f64>,
    /// Trace length (CARLA's `range`), m: hits farther along the ray are not returned.
    pub range_m: f64,
    /// Per channel, the direction's components along the azimuth's cosine,
    /// its sine and the constant part (mount rotation applied once).
    basis: Vec<[Vector3<f64>; 3]>,
    /// [`Self::is_level`], found once.
    level: bool,
}

impl Sensor {
    /// A sensor `height_m` above the road, level, with the given channels.
    #[must_use]
    pub fn new(height_m: f64, elevations_deg: Vec<f64>, range_m: f64) -> Self {
        let (sin_el, cos_el): (Vec<f64>, Vec<f64>) = elevations_deg
            .iter()
            .map(|e| e.to_radians().sin_cos())
            .unzip();
        let mount = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, height_m),
            UnitQuaternion::identity(),
        );
        let basis = cos_el
            .iter()
            .zip(&sin_el)
            .map(|(&c, &s)| {
                [
                    mount.rotation * Vector3::new(c, 0.0, 0.0),
                    mount.rotation * Vector3::new(0.0, c, 0.0),
                    mount.rotation * Vector3::new(0.0, 0.0, s),
                ]
            })
            .collect();
        let mut sensor = Self {
            mount,
            elevations_deg,
            cos_el,
            sin_el,
            range_m,
            basis,
            level: false,
        };
        sensor.level = sensor.find_level();
        sensor
    }

    /// Whether the mount is level and every channel's direction is exactly
    /// `(cos·cos az, cos·sin az, sin)` of its elevation: then its vertical
    /// component is the same at every azimuth, bit for bit, and so is the
    /// distance to the ground plane.
    #[must_use]
    pub fn is_level(&self) -> bool {
        self.level
    }

    fn find_level(&self) -> bool {
        self.mount.rotation == UnitQuaternion::identity()
            && self
                .basis
                .iter()
                .zip(self.cos_el.iter().zip(&self.sin_el))
                .all(|([a, b, c], (&co, &si))| {
                    *a == Vector3::new(co, 0.0, 0.0)
                        && *b == Vector3::new(0.0, co, 0.0)
                        && *c == Vector3::new(0.0, 0.0, si)
                })
    }

    /// The sensor's origin in the road frame.
    #[must_use]
    pub fn origin(&self) -> Point3<f64> {
        self.mount * Point3::origin()
    }

    /// Unit direction (road frame) of channel `ch` at azimuth `(cos, sin)`:
    /// on a level sensor `(cos·cos az, cos·sin az, sin)` of the elevation
    /// (the basis sum's values up to the sign of a zero component).
    #[must_use]
    #[inline]
    pub fn direction(&self, ch: usize, cos_az: f64, sin_az: f64) -> Vector3<f64> {
        if self.level {
            let c = self.cos_el[ch];
            Vector3::new(c * cos_az, c * sin_az, self.sin_el[ch])
        } else {
            let [a, b, c] = &self.basis[ch];
            a * cos_az + b * sin_az + c
        }
    }

    /// A point of the road frame in the sensor frame (a level mount: the
    /// translation alone, the same values as the isometry's inverse up to
    /// the sign of zero).
    #[must_use]
    pub fn to_sensor(&self, p: &Point3<f64>) -> Point3<f64> {
        if self.mount.rotation == UnitQuaternion::identity() {
            p - self.mount.translation.vector
        } else {
            self.mount.inverse_transform_point(p)
        }
    }
}

/// What a ray hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Surface {
    /// The road plane.
    Ground,
    /// A static box (building).
    Building,
    /// Vehicle `j` (0: from the left, 1: from the right).
    Vehicle(usize),
}

/// A ray hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray: the slant range, m.
    pub range_m: f64,
    /// |cos| of the angle between the ray and the surface normal.
    pub cos_incidence: f64,
    /// Hit point in the road frame; the coordinate across the face entered
    /// is the face's own (no rounding off the plane).
    pub point: Point3<f64>,
    /// What was hit.
    pub surface: Surface,
}

/// Entry and exit parameters of the slab `[lo, hi]` along one axis for a ray
/// starting at `o` with direction component `d`; `None` if parallel outside.
#[inline]
fn slab(lo: f64, hi: f64, o: f64, d: f64) -> Option<(f64, f64)> {
    if d == 0.0 {
        if lo <= o && o <= hi {
            Some((f64::NEG_INFINITY, f64::INFINITY))
        } else {
            None
        }
    } else {
        let a = (lo - o) / d;
        let b = (hi - o) / d;
        // Neither is NaN (finite bounds, d ≠ 0): the ordered pair.
        Some(if a <= b { (a, b) } else { (b, a) })
    }
}

/// Slab test against `[lo, hi]` (3 axes): entry distance, the axis entered
/// and the face value on that axis, if the ray enters at a positive distance.
#[inline]
fn slab3(
    lo: &Point3<f64>,
    hi: &Point3<f64>,
    o: &Point3<f64>,
    d: &Vector3<f64>,
) -> Option<(f64, usize, f64)> {
    let z = slab(lo.z, hi.z, o.z, d.z)?;
    slab3_given_z(lo, hi, o, d, z)
}

/// [`slab3`] with the z slab's `(entry, exit)` given (the same for every
/// azimuth of a channel of a level sensor).
#[inline]
fn slab3_given_z(
    lo: &Point3<f64>,
    hi: &Point3<f64>,
    o: &Point3<f64>,
    d: &Vector3<f64>,
    z: (f64, f64),
) -> Option<(f64, usize, f64)> {
    let x = slab(lo.x, hi.x, o.x, d.x)?;
    let y = slab(lo.y, hi.y, o.y, d.y)?;
    // The entry is the last slab entered (the first axis on ties), the exit
    // the first left: x, y, z in turn.
    let (mut t_in, mut axis) = (f64::NEG_INFINITY, 0);
    let mut t_out = f64::INFINITY;
    for (k, (a, b)) in [(0, x), (1, y), (2, z)] {
        if a > t_in {
            t_in = a;
            axis = k;
        }
        if b < t_out {
            t_out = b;
        }
    }
    if t_in > t_out || t_in <= 0.0 {
        return None;
    }
    let (dk, lo_k, hi_k) = match axis {
        0 => (d.x, lo.x, hi.x),
        1 => (d.y, lo.y, hi.y),
        _ => (d.z, lo.z, hi.z),
    };
    let face = if dk > 0.0 { lo_k } else { hi_k };
    Some((t_in, axis, face))
}

/// Where a ray enters a static box: distance, axis and face value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Distance along the ray, m.
    pub range_m: f64,
    axis: usize,
    face: f64,
}

/// An axis-aligned box of the road frame (a building).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticBox {
    /// Minimum corner.
    pub min: Point3<f64>,
    /// Maximum corner.
    pub max: Point3<f64>,
}

impl StaticBox {
    /// The first hit of the ray `o + t·d` (`d` unit), if any.
    #[must_use]
    pub fn ray_hit(&self, o: &Point3<f64>, d: &Vector3<f64>) -> Option<Hit> {
        let (range_m, axis, face) = slab3(&self.min, &self.max, o, d)?;
        Some(Self::hit(
            o,
            d,
            Entry {
                range_m,
                axis,
                face,
            },
        ))
    }

    /// The z slab `(entry, exit)` of rays from `o` with vertical component
    /// `d_z`; `None` if they never lie in the box's height band.
    #[must_use]
    pub fn z_slab(&self, o: &Point3<f64>, d_z: f64) -> Option<(f64, f64)> {
        slab(self.min.z, self.max.z, o.z, d_z)
    }

    /// Where the ray `o + t·d` enters, given its [`Self::z_slab`]: the same
    /// as [`Self::ray_hit`]'s range, bit for bit.
    #[must_use]
    pub fn entry(&self, o: &Point3<f64>, d: &Vector3<f64>, z: (f64, f64)) -> Option<Entry> {
        let (range_m, axis, face) = slab3_given_z(&self.min, &self.max, o, d, z)?;
        Some(Entry {
            range_m,
            axis,
            face,
        })
    }

    /// The hit of the ray `o + t·d` at its entry `e`: as [`Self::ray_hit`].
    #[must_use]
    pub fn hit(o: &Point3<f64>, d: &Vector3<f64>, e: Entry) -> Hit {
        let Entry {
            range_m: t,
            axis,
            face,
        } = e;
        let mut point = o + d * t;
        // The axis by name, not by index: keeps the point in registers.
        let cos_incidence = match axis {
            0 => {
                point.x = face;
                d.x.abs()
            }
            1 => {
                point.y = face;
                d.y.abs()
            }
            _ => {
                point.z = face;
                d.z.abs()
            }
        };
        Hit {
            range_m: t,
            cos_incidence,
            point,
            surface: Surface::Building,
        }
    }

    /// The footprint as a 2D box `(x0, x1, y0, y1)`.
    #[must_use]
    pub fn footprint(&self) -> [f64; 4] {
        [self.min.x, self.max.x, self.min.y, self.max.y]
    }

    /// Height range `(z0, z1)`.
    #[must_use]
    pub fn heights(&self) -> (f64, f64) {
        (self.min.z, self.max.z)
    }
}

/// A posed box: a vehicle (centre and heading as an isometry, half extents
/// along its own axes: x forward, y left, z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosedBox {
    /// Box frame in the road frame (origin at the box centre).
    pub pose: Isometry3<f64>,
    /// Half extents, m.
    pub half: Vector3<f64>,
}

impl PosedBox {
    /// A box of `size` (length, width, height) standing on the road at
    /// `(x, y)` and heading `yaw_rad` (from +x towards +y).
    #[must_use]
    pub fn on_road(x: f64, y: f64, yaw_rad: f64, size: Vector3<f64>) -> Self {
        Self::above_road(x, y, 0.0, yaw_rad, size)
    }

    /// A box of `size` whose bottom face lies `clearance_m` above the road
    /// (a car's body over its ground clearance), centred at `(x, y)`.
    #[must_use]
    pub fn above_road(x: f64, y: f64, clearance_m: f64, yaw_rad: f64, size: Vector3<f64>) -> Self {
        Self {
            pose: Isometry3::from_parts(
                Translation3::new(x, y, clearance_m + 0.5 * size.z),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw_rad),
            ),
            half: size * 0.5,
        }
    }

    /// The first hit of the ray `o + t·d` (`d` unit), if any, tagged `surface`.
    #[must_use]
    pub fn ray_hit(&self, o: &Point3<f64>, d: &Vector3<f64>, surface: Surface) -> Option<Hit> {
        let lo = self.pose.inverse_transform_point(o);
        let ld = self.pose.inverse_transform_vector(d);
        let hi = Point3::from(self.half);
        let lo_corner = Point3::from(-self.half);
        let (t, axis, _) = slab3(&lo_corner, &hi, &lo, &ld)?;
        Some(Hit {
            range_m: t,
            cos_incidence: ld[axis].abs(),
            point: o + d * t,
            surface,
        })
    }

    /// The eight corners in the road frame.
    #[must_use]
    pub fn corners(&self) -> [Point3<f64>; 8] {
        let h = self.half;
        let mut out = [Point3::origin(); 8];
        for (i, c) in out.iter_mut().enumerate() {
            let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            *c = self.pose * Point3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z);
        }
        out
    }

    /// The axis-aligned footprint `(x0, x1, y0, y1)` and height range of the box.
    #[must_use]
    pub fn bounds(&self) -> ([f64; 4], (f64, f64)) {
        let c = self.corners();
        let fold = |f: fn(&Point3<f64>) -> f64, pick: fn(f64, f64) -> f64, init: f64| {
            c.iter().map(f).fold(init, pick)
        };
        (
            [
                fold(|p| p.x, f64::min, f64::INFINITY),
                fold(|p| p.x, f64::max, f64::NEG_INFINITY),
                fold(|p| p.y, f64::min, f64::INFINITY),
                fold(|p| p.y, f64::max, f64::NEG_INFINITY),
            ],
            (
                fold(|p| p.z, f64::min, f64::INFINITY),
                fold(|p| p.z, f64::max, f64::NEG_INFINITY),
            ),
        )
    }

    /// The box centre in the road frame.
    #[must_use]
    pub fn centre(&self) -> Point3<f64> {
        self.pose * Point3::origin()
    }
}

/// The ground hit of the ray `o + t·d`: the plane `z = 0` if the ray points down.
#[must_use]
pub fn ground_hit(o: &Point3<f64>, d: &Vector3<f64>) -> Option<Hit> {
    if d.z >= 0.0 || o.z <= 0.0 {
        return None;
    }
    let t = -o.z / d.z;
    Some(Hit {
        range_m: t,
        cos_incidence: d.z.abs(),
        point: Point3::new(o.x + t * d.x, o.y + t * d.y, 0.0),
        surface: Surface::Ground,
    })
}

/// Whether a channel of elevation tangent `tan_el` from height `h` can meet
/// heights `[z0, z1]` at horizontal distances `[d0, d1]` before it ends at
/// horizontal distance `d_end` (its trace length or the ground): a
/// conservative bound (padded by `pad`), used to skip boxes a channel cannot hit.
#[must_use]
pub fn channel_may_reach(
    h: f64,
    tan_el: f64,
    (z0, z1): (f64, f64),
    (d0, d1): (f64, f64),
    d_end: f64,
    pad: f64,
) -> bool {
    let a = (d0 - pad).max(0.0);
    let b = (d1 + pad).min(d_end + pad);
    if a > b {
        return false;
    }
    let za = h + a * tan_el;
    let zb = h + b * tan_el;
    let (lo, hi) = if za <= zb { (za, zb) } else { (zb, za) };
    lo <= z1 + pad && hi >= z0 - pad
}

/// Horizontal distance range from the origin to a 2D box `(x0, x1, y0, y1)`:
/// nearest point and farthest corner.
#[must_use]
pub fn footprint_distances(f: [f64; 4]) -> (f64, f64) {
    let [x0, x1, y0, y1] = f;
    let nx = if x0 > 0.0 {
        x0
    } else if x1 < 0.0 {
        -x1
    } else {
        0.0
    };
    let ny = if y0 > 0.0 {
        y0
    } else if y1 < 0.0 {
        -y1
    } else {
        0.0
    };
    let fx = x0.abs().max(x1.abs());
    let fy = y0.abs().max(y1.abs());
    (nx.hypot(ny), fx.hypot(fy))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn carla_default_channels() {
        let e = carla_elevations_deg(64, 10.0, -30.0);
        assert_eq!(e.len(), 64);
        assert_eq!(e[0], 10.0);
        assert_relative_eq!(e[63], -30.0, epsilon = 1e-12);
        assert_relative_eq!(e[1] - e[0], -40.0 / 63.0, epsilon = 1e-12);
        assert_eq!(carla_elevations_deg(1, 10.0, -30.0), vec![10.0]);
    }

    #[test]
    fn posed_box_hits_and_incidence() {
        // A 4 × 2 × 1.5 box heading +y, centred at (10, 0): its side faces -x.
        let b = PosedBox::on_road(
            10.0,
            0.0,
            std::f64::consts::FRAC_PI_2,
            Vector3::new(4.0, 2.0, 1.5),
        );
        let o = Point3::new(0.0, 0.0, 1.0);
        let h = b.ray_hit(&o, &Vector3::x(), Surface::Vehicle(1)).unwrap();
        assert_relative_eq!(h.range_m, 9.0, epsilon = 1e-12);
        assert_relative_eq!(h.cos_incidence, 1.0, epsilon = 1e-12);
        assert!(b.ray_hit(&o, &-Vector3::x(), Surface::Vehicle(1)).is_none());
        // Above the roof: misses.
        let high = Point3::new(0.0, 0.0, 2.0);
        assert!(b
            .ray_hit(&high, &Vector3::x(), Surface::Vehicle(1))
            .is_none());
        let (f, z) = b.bounds();
        assert_relative_eq!(f[0], 9.0, epsilon = 1e-12);
        assert_relative_eq!(f[3], 2.0, epsilon = 1e-12);
        assert_relative_eq!(z.1, 1.5, epsilon = 1e-12);
    }

    #[test]
    fn static_hit_lands_on_the_face() {
        let b = StaticBox {
            min: Point3::new(12.0, -50.0, 0.0),
            max: Point3::new(40.0, 50.0, 10.0),
        };
        let o = Point3::new(0.0, 0.0, 3.0);
        let a = (-37.0f64).to_radians();
        let d = Vector3::new(a.cos(), a.sin(), 0.0);
        let h = b.ray_hit(&o, &d).unwrap();
        assert_eq!(h.point.x, 12.0);
        assert_relative_eq!(h.range_m, 12.0 / a.cos(), epsilon = 1e-12);
    }

    #[test]
    fn ground_ring() {
        let o = Point3::new(0.0, 0.0, 3.0);
        let e = (-10.0f64).to_radians();
        let d = Vector3::new(e.cos(), 0.0, e.sin());
        let h = ground_hit(&o, &d).unwrap();
        assert_relative_eq!(h.point.x, 3.0 / 10f64.to_radians().tan(), epsilon = 1e-9);
        assert!(ground_hit(&o, &Vector3::x()).is_none());
    }

    #[test]
    fn level_direction_is_the_basis_sum() {
        let s = Sensor::new(3.0, carla_elevations_deg(64, 10.0, -30.0), 100.0);
        assert!(s.is_level());
        for i in 0..3600 {
            let (sin_az, cos_az) = (f64::from(i) * 0.1).to_radians().sin_cos();
            for ch in 0..64 {
                let [a, b, c] = &s.basis[ch];
                let sum = a * cos_az + b * sin_az + c;
                // Equal values (== treats the two zeros alike).
                assert_eq!(s.direction(ch, cos_az, sin_az), sum);
                assert_eq!(
                    s.direction(ch, cos_az, sin_az).z.to_bits(),
                    s.sin_el[ch].to_bits()
                );
            }
        }
        let p = Point3::new(1.5, -2.5, 0.0);
        assert_eq!(s.to_sensor(&p), s.mount.inverse_transform_point(&p));
    }
}
