//! The sensor's mounting yaw from the bag's static transforms
//! (`tf2_msgs/msg/TFMessage` on `/tf_static`).
//!
//! Each `geometry_msgs/TransformStamped` gives the rotation of its
//! `child_frame_id` in its `header.frame_id` (ROS's tf convention: the
//! quaternion turns a vector in the child frame into the parent frame).
//! [`TfTree::rotation`] composes them along the tree from any frame to any
//! other frame with the same root, and [`mounting_yaw_deg`] reads the yaw
//! of the cloud frame's x axis in the vehicle frame (counter-clockwise
//! about z, ISO 8855 / REP 103) from that rotation, refusing one whose roll
//! or pitch tilts the cloud frame's z axis more than a tolerance from the
//! vehicle's: replay models the mounting as a yaw alone.

use std::collections::BTreeMap;

/// A quaternion `[x, y, z, w]`.
pub type Quat = [f64; 4];

const IDENTITY: Quat = [0.0, 0.0, 0.0, 1.0];

/// Hamilton product `a · b` (apply `b`, then `a`).
#[must_use]
pub fn mul(a: Quat, b: Quat) -> Quat {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

fn conj([x, y, z, w]: Quat) -> Quat {
    [-x, -y, -z, w]
}

/// `q / |q|`, computed as `(q / m) / |q / m|` with `m` the largest
/// component's magnitude (so `|q / m|` lies in `[1, 2]`: no overflow or
/// underflow whatever the scale); `None` when `q` is zero or not finite.
#[must_use]
pub fn normalized(q: Quat) -> Option<Quat> {
    if !q.iter().all(|v| v.is_finite()) {
        return None;
    }
    let m = q.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if m == 0.0 {
        return None;
    }
    let s = q.map(|v| v / m);
    let norm = s.iter().map(|v| v * v).sum::<f64>().sqrt();
    Some(s.map(|v| v / norm))
}

/// Why a transform cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub enum TfError {
    /// The quaternion has a zero, huge or non-finite norm.
    BadQuaternion(Quat),
    /// Following the parents from this frame comes back to it.
    Cycle(String),
}

impl std::fmt::Display for TfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BadQuaternion(q) => write!(f, "rotation {q:?} is not a rotation quaternion"),
            Self::Cycle(frame) => write!(f, "the transforms from {frame:?} form a cycle"),
        }
    }
}

/// Static transforms, child frame → (parent frame, rotation child → parent).
#[derive(Debug, Clone, Default)]
pub struct TfTree {
    parents: BTreeMap<String, (String, Quat)>,
}

impl TfTree {
    /// Adds (or replaces) the transform of `child` in `parent`; the
    /// quaternion is normalised (a norm off 1 by rounding is common), any
    /// finite non-zero one: scaled by its largest component first, so
    /// neither squaring overflows nor underflows ([`normalized`]).
    pub fn insert(&mut self, parent: &str, child: &str, q: Quat) -> Result<(), TfError> {
        let q = normalized(q).ok_or(TfError::BadQuaternion(q))?;
        self.parents
            .insert(child.to_owned(), (parent.to_owned(), q));
        Ok(())
    }

    /// Whether no transform was read.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.parents.is_empty()
    }

    /// (root frame, rotation `frame` → root).
    fn to_root<'a>(&'a self, frame: &'a str) -> Result<(&'a str, Quat), TfError> {
        let mut q = IDENTITY;
        let mut cur = frame;
        for _ in 0..=self.parents.len() {
            match self.parents.get(cur) {
                Some((parent, r)) => {
                    q = mul(*r, q);
                    cur = parent;
                }
                None => return Ok((cur, q)),
            }
        }
        Err(TfError::Cycle(frame.to_owned()))
    }

    /// The rotation that turns a vector in `from` into `to`; `None` when
    /// the two frames are not in one tree.
    pub fn rotation(&self, from: &str, to: &str) -> Result<Option<Quat>, TfError> {
        let (root_from, q_from) = self.to_root(from)?;
        let (root_to, q_to) = self.to_root(to)?;
        Ok((root_from == root_to).then(|| mul(conj(q_to), q_from)))
    }
}

/// `v` turned by the unit quaternion `q`: `v + 2w(u×v) + 2u×(u×v)`, with
/// `u` the quaternion's vector part.
#[must_use]
pub fn rotate(q: Quat, v: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let u = [x, y, z];
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [
        v[0] + w * t[0] + ut[0],
        v[1] + w * t[1] + ut[1],
        v[2] + w * t[2] + ut[2],
    ]
}

/// The mounting read from a rotation `q` (cloud frame → vehicle frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mounting {
    /// Yaw of the cloud frame's x axis in the vehicle frame, degrees
    /// counter-clockwise about z (`atan2(R₁₀, R₀₀)`).
    pub yaw_deg: f64,
    /// Angle between the cloud frame's z axis and the vehicle's, degrees
    /// (`acos(R₂₂)`: the roll and pitch together).
    pub tilt_deg: f64,
}

/// The yaw and tilt of a unit quaternion's rotation matrix `R`.
#[must_use]
pub fn mounting(q: Quat) -> Mounting {
    let [x, y, z, w] = q;
    let r00 = 1.0 - 2.0 * (y * y + z * z);
    let r10 = 2.0 * (x * y + w * z);
    let r22 = 1.0 - 2.0 * (x * x + y * y);
    Mounting {
        yaw_deg: r10.atan2(r00).to_degrees(),
        tilt_deg: r22.clamp(-1.0, 1.0).acos().to_degrees(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation of `deg` about the unit axis `a`.
    fn axis_angle(a: [f64; 3], deg: f64) -> Quat {
        let h = deg.to_radians() / 2.0;
        [a[0] * h.sin(), a[1] * h.sin(), a[2] * h.sin(), h.cos()]
    }

    /// `R · v` by the matrix of a unit quaternion, written out (a reference
    /// independent of `mul`).
    fn rotate(q: Quat, v: [f64; 3]) -> [f64; 3] {
        let [x, y, z, w] = q;
        let m = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    }

    #[test]
    fn a_pure_yaw_is_read_back_with_no_tilt() {
        for deg in [-179.0, -90.0, -30.0, 0.0, 12.5, 90.0, 179.0] {
            let m = mounting(axis_angle([0.0, 0.0, 1.0], deg));
            assert!((m.yaw_deg - deg).abs() < 1e-9, "{deg}: {m:?}");
            assert!(m.tilt_deg < 1e-6, "{deg}: {m:?}");
        }
    }

    #[test]
    fn the_yaw_is_the_azimuth_of_the_turned_x_axis_and_the_tilt_that_of_z() {
        // Against the matrix written out: any rotation.
        let qs = [
            mul(
                axis_angle([0.0, 0.0, 1.0], 40.0),
                axis_angle([1.0, 0.0, 0.0], 3.0),
            ),
            mul(
                axis_angle([0.0, 1.0, 0.0], -2.0),
                axis_angle([0.0, 0.0, 1.0], -120.0),
            ),
            axis_angle([0.6, 0.0, 0.8], 25.0),
        ];
        for q in qs {
            let m = mounting(q);
            let xv = rotate(q, [1.0, 0.0, 0.0]);
            let zv = rotate(q, [0.0, 0.0, 1.0]);
            assert!((m.yaw_deg - xv[1].atan2(xv[0]).to_degrees()).abs() < 1e-9);
            assert!((m.tilt_deg - zv[2].acos().to_degrees()).abs() < 1e-6);
        }
        // A 3° roll under a 40° yaw: tilt 3°.
        let m = mounting(qs[0]);
        assert!((m.tilt_deg - 3.0).abs() < 1e-9 && (m.yaw_deg - 40.0).abs() < 1e-9);
    }

    #[test]
    fn rotations_compose_along_the_tree_either_way() {
        let mut t = TfTree::default();
        // base_link → roof (yaw 30°) → lidar (yaw 15°); a camera off base_link.
        t.insert("base_link", "roof", axis_angle([0.0, 0.0, 1.0], 30.0))
            .unwrap();
        // Not normalised: the tree normalises.
        let q = axis_angle([0.0, 0.0, 1.0], 15.0).map(|v| v * 2.0);
        t.insert("roof", "lidar", q).unwrap();
        t.insert("base_link", "cam", axis_angle([0.0, 0.0, 1.0], -50.0))
            .unwrap();
        let yaw = |from, to| mounting(t.rotation(from, to).unwrap().unwrap()).yaw_deg;
        assert!((yaw("lidar", "base_link") - 45.0).abs() < 1e-9);
        assert!((yaw("base_link", "lidar") + 45.0).abs() < 1e-9);
        assert!((yaw("lidar", "cam") - 95.0).abs() < 1e-9);
        assert!((yaw("base_link", "base_link")).abs() < 1e-12);
        assert_eq!(t.rotation("lidar", "map").unwrap(), None);
        // A cycle is an error, not a hang.
        t.insert("lidar", "base_link", IDENTITY).unwrap();
        assert!(matches!(t.rotation("cam", "lidar"), Err(TfError::Cycle(_))));
        assert!(matches!(
            t.insert("a", "b", [0.0; 4]),
            Err(TfError::BadQuaternion(_))
        ));
        assert!(t.insert("a", "b", [f64::NAN, 0.0, 0.0, 1.0]).is_err());
    }

    #[test]
    fn quaternions_of_any_finite_scale_normalise_to_the_same_rotation() {
        let q = axis_angle([0.0, 0.0, 1.0], 37.0);
        for scale in [1e-200, 1e-300, 1e-310, 1e200, 1e300, 1.7e308] {
            let s = q.map(|v| v * scale);
            if s.iter().all(|v| *v == 0.0) {
                continue;
            }
            let mut t = TfTree::default();
            t.insert("base_link", "lidar", s).unwrap();
            let m = mounting(t.rotation("lidar", "base_link").unwrap().unwrap());
            // Subnormal scales lose digits of the components themselves.
            let tol = if scale < 1e-300 { 1e-3 } else { 1e-9 };
            assert!((m.yaw_deg - 37.0).abs() < tol, "{scale}: {m:?}");
        }
        assert_eq!(normalized([0.0; 4]), None);
        assert_eq!(normalized([f64::INFINITY, 0.0, 0.0, 0.0]), None);
        assert_eq!(
            normalized([0.0, 0.0, 0.0, -1e300]),
            Some([0.0, 0.0, 0.0, -1.0])
        );
    }
}
