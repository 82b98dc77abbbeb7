//! CDR (OMG XCDR1, the ROS 2 wire format in rosbag2 MCAP files) for the
//! three message types replay reads and writes: `geometry_msgs/msg/Vector3Stamped`,
//! `std_msgs/msg/Float64` and `sensor_msgs/msg/PointCloud2`.
//!
//! Hand-written rather than serde-based (`cdr-encoding`): these three types
//! are fixed, and a [`PointCloud2`] borrows its point bytes from the message
//! instead of copying several megabytes per cloud.
//!
//! Encoding rules (OMG DDS-XTypes 1.3, §7.4.1 "XCDR1"): a 4-byte
//! encapsulation header (`00 00` big-endian, `00 01` little-endian, then two
//! option bytes), then the fields, each primitive aligned to its own size
//! counted from the end of that header; a string is a `u32` length that
//! includes the terminating NUL, then the bytes and the NUL; a sequence is a
//! `u32` element count, then the elements.

use super::ReplayError;

/// A decoding failure: what was being read and why.
fn bad(what: &str, reason: impl Into<String>) -> ReplayError {
    ReplayError::Message {
        field: what.to_owned(),
        reason: reason.into(),
    }
}

/// Reads CDR from one message (encapsulation header included).
pub struct Reader<'a> {
    buf: &'a [u8],
    /// Position in `buf` (alignment is counted from 4, the header's end).
    pos: usize,
    little: bool,
}

impl<'a> Reader<'a> {
    /// Checks the encapsulation header (plain CDR, either byte order).
    pub fn new(buf: &'a [u8]) -> Result<Self, ReplayError> {
        if buf.len() < 4 {
            return Err(bad(
                "encapsulation",
                format!("{} bytes, shorter than the 4-byte CDR header", buf.len()),
            ));
        }
        let little = match (buf[0], buf[1]) {
            (0, 0) => false,
            (0, 1) => true,
            (a, b) => {
                return Err(bad(
                    "encapsulation",
                    format!("kind 0x{a:02X}{b:02X} is not plain CDR (0x0000 or 0x0001)"),
                ))
            }
        };
        Ok(Self {
            buf,
            pos: 4,
            little,
        })
    }

    fn align(&mut self, n: usize) {
        let rel = self.pos - 4;
        self.pos += (n - rel % n) % n;
    }

    fn take(&mut self, what: &str, n: usize) -> Result<&'a [u8], ReplayError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        match end {
            Some(end) => {
                let s = &self.buf[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(bad(
                what,
                format!(
                    "needs {n} bytes at offset {} of a {}-byte message",
                    self.pos,
                    self.buf.len()
                ),
            )),
        }
    }

    /// One byte.
    pub fn u8(&mut self, what: &str) -> Result<u8, ReplayError> {
        Ok(self.take(what, 1)?[0])
    }

    /// A boolean (one byte, 0 or 1).
    pub fn bool(&mut self, what: &str) -> Result<bool, ReplayError> {
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(bad(what, format!("{v} is not a boolean (0 or 1)"))),
        }
    }

    /// A `u32`.
    pub fn u32(&mut self, what: &str) -> Result<u32, ReplayError> {
        self.align(4);
        let b: [u8; 4] = self.take(what, 4)?.try_into().unwrap_or([0; 4]);
        Ok(if self.little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    }

    /// An `i32`.
    pub fn i32(&mut self, what: &str) -> Result<i32, ReplayError> {
        Ok(self.u32(what)? as i32)
    }

    /// An `f64`.
    pub fn f64(&mut self, what: &str) -> Result<f64, ReplayError> {
        self.align(8);
        let b: [u8; 8] = self.take(what, 8)?.try_into().unwrap_or([0; 8]);
        Ok(if self.little {
            f64::from_le_bytes(b)
        } else {
            f64::from_be_bytes(b)
        })
    }

    /// A string (length with NUL, bytes, NUL).
    pub fn string(&mut self, what: &str) -> Result<&'a str, ReplayError> {
        let n = self.u32(what)? as usize;
        if n == 0 {
            // Some writers send an empty string as length 0.
            return Ok("");
        }
        let bytes = self.take(what, n)?;
        let (text, nul) = bytes.split_at(n - 1);
        if nul != [0] {
            return Err(bad(what, "string not terminated by a NUL byte"));
        }
        std::str::from_utf8(text).map_err(|e| bad(what, format!("not UTF-8 ({e})")))
    }

    /// A `sequence<uint8>`, borrowed.
    pub fn bytes(&mut self, what: &str) -> Result<&'a [u8], ReplayError> {
        let n = self.u32(what)? as usize;
        self.take(what, n)
    }
}

/// Writes little-endian CDR.
pub struct Writer {
    buf: Vec<u8>,
}

impl Writer {
    /// An empty message (the little-endian encapsulation header).
    #[must_use]
    pub fn new(capacity: usize) -> Self {
        let mut buf = Vec::with_capacity(capacity + 4);
        buf.extend_from_slice(&[0, 1, 0, 0]);
        Self { buf }
    }

    fn align(&mut self, n: usize) {
        let rel = self.buf.len() - 4;
        let pad = (n - rel % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// One byte.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// A `u32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `i32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `f32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `f64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A string (its length saturates at `u32::MAX`: never reached by the
    /// frame ids and field names written here).
    pub fn string(&mut self, s: &str) {
        self.u32(u32::try_from(s.len() + 1).unwrap_or(u32::MAX));
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A `sequence<uint8>` from parts written one after another.
    pub fn bytes_from<'a>(&mut self, total: usize, parts: impl Iterator<Item = &'a [u8]>) {
        self.u32(u32::try_from(total).unwrap_or(u32::MAX));
        let start = self.buf.len();
        self.buf.reserve(total);
        for p in parts {
            self.buf.extend_from_slice(p);
        }
        debug_assert_eq!(self.buf.len() - start, total);
    }

    /// The message.
    #[must_use]
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header<'a> {
    /// `builtin_interfaces/Time.sec`.
    pub sec: i32,
    /// `builtin_interfaces/Time.nanosec`.
    pub nanosec: u32,
    /// `frame_id`.
    pub frame_id: &'a str,
}

impl<'a> Header<'a> {
    fn read(r: &mut Reader<'a>) -> Result<Self, ReplayError> {
        Ok(Self {
            sec: r.i32("header.stamp.sec")?,
            nanosec: r.u32("header.stamp.nanosec")?,
            frame_id: r.string("header.frame_id")?,
        })
    }

    /// Writes the header.
    pub fn write(&self, w: &mut Writer) {
        w.i32(self.sec);
        w.u32(self.nanosec);
        w.string(self.frame_id);
    }
}

/// `geometry_msgs/msg/Vector3Stamped`.
#[derive(Debug, Clone, PartialEq)]
pub struct Vector3Stamped<'a> {
    /// Header.
    pub header: Header<'a>,
    /// The vector.
    pub xyz: [f64; 3],
}

impl<'a> Vector3Stamped<'a> {
    /// Decodes one message.
    pub fn decode(buf: &'a [u8]) -> Result<Self, ReplayError> {
        let mut r = Reader::new(buf)?;
        let header = Header::read(&mut r)?;
        let xyz = [r.f64("vector.x")?, r.f64("vector.y")?, r.f64("vector.z")?];
        Ok(Self { header, xyz })
    }

    /// Encodes it (little-endian).
    #[must_use]
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::new(64);
        self.header.write(&mut w);
        for v in self.xyz {
            w.f64(v);
        }
        w.finish()
    }
}

/// `std_msgs/msg/Float64`: the value.
pub fn decode_float64(buf: &[u8]) -> Result<f64, ReplayError> {
    Reader::new(buf)?.f64("data")
}

/// `std_msgs/msg/Float64`, encoded (little-endian).
#[must_use]
pub fn encode_float64(v: f64) -> Vec<u8> {
    let mut w = Writer::new(8);
    w.f64(v);
    w.finish()
}

/// A `std_msgs/msg/String`.
#[must_use]
pub fn encode_string(s: &str) -> Vec<u8> {
    let mut w = Writer::new(s.len() + 8);
    w.string(s);
    w.finish()
}

/// The text of a `std_msgs/msg/String`.
pub fn decode_string(buf: &[u8]) -> Result<&str, ReplayError> {
    Reader::new(buf)?.string("data")
}

/// `sensor_msgs/msg/PointField.datatype` values.
pub mod datatype {
    /// `INT8`.
    pub const INT8: u8 = 1;
    /// `UINT8`.
    pub const UINT8: u8 = 2;
    /// `INT16`.
    pub const INT16: u8 = 3;
    /// `UINT16`.
    pub const UINT16: u8 = 4;
    /// `INT32`.
    pub const INT32: u8 = 5;
    /// `UINT32`.
    pub const UINT32: u8 = 6;
    /// `FLOAT32`.
    pub const FLOAT32: u8 = 7;
    /// `FLOAT64`.
    pub const FLOAT64: u8 = 8;

    /// Size of one element, bytes (`None`: not a known datatype).
    #[must_use]
    pub fn size(t: u8) -> Option<usize> {
        match t {
            INT8 | UINT8 => Some(1),
            INT16 | UINT16 => Some(2),
            INT32 | UINT32 | FLOAT32 => Some(4),
            FLOAT64 => Some(8),
            _ => None,
        }
    }
}

/// `sensor_msgs/msg/PointField`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointField<'a> {
    /// Name (`x`, `y`, `z`, `intensity`, …).
    pub name: &'a str,
    /// Byte offset in a point.
    pub offset: u32,
    /// [`datatype`].
    pub datatype: u8,
    /// Elements.
    pub count: u32,
}

/// `sensor_msgs/msg/PointCloud2`, its point bytes borrowed.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud2<'a> {
    /// Header.
    pub header: Header<'a>,
    /// Rows.
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// Layout of a point.
    pub fields: Vec<PointField<'a>>,
    /// Byte order of `data`.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points, `height` rows of `row_step` bytes.
    pub data: &'a [u8],
    /// No invalid (NaN) points.
    pub is_dense: bool,
}

impl<'a> PointCloud2<'a> {
    /// Decodes one message (the layout is checked by [`PointCloud2::xyz`]).
    pub fn decode(buf: &'a [u8]) -> Result<Self, ReplayError> {
        let mut r = Reader::new(buf)?;
        let header = Header::read(&mut r)?;
        let height = r.u32("height")?;
        let width = r.u32("width")?;
        let n = r.u32("fields")? as usize;
        // Each field takes at least 13 bytes: a count this large is corrupt.
        if n > buf.len() / 13 {
            return Err(bad(
                "fields",
                format!("{n} fields in a {}-byte message", buf.len()),
            ));
        }
        let mut fields = Vec::with_capacity(n);
        for _ in 0..n {
            fields.push(PointField {
                name: r.string("fields[].name")?,
                offset: r.u32("fields[].offset")?,
                datatype: r.u8("fields[].datatype")?,
                count: r.u32("fields[].count")?,
            });
        }
        let is_bigendian = r.bool("is_bigendian")?;
        let point_step = r.u32("point_step")?;
        let row_step = r.u32("row_step")?;
        let data = r.bytes("data")?;
        let is_dense = r.bool("is_dense")?;
        Ok(Self {
            header,
            height,
            width,
            fields,
            is_bigendian,
            point_step,
            row_step,
            data,
            is_dense,
        })
    }

    /// The x, y, z layout: checks the fields, steps and data length.
    pub fn xyz(&self) -> Result<XyzLayout, ReplayError> {
        let mut offsets = [(0usize, false); 3];
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let f = self
                .fields
                .iter()
                .find(|f| f.name == *axis)
                .ok_or_else(|| bad("fields", format!("no field named {axis}")))?;
            let wide = match f.datatype {
                datatype::FLOAT32 => false,
                datatype::FLOAT64 => true,
                t => {
                    return Err(bad(
                        "fields",
                        format!("field {axis} has datatype {t}, not FLOAT32 (7) or FLOAT64 (8)"),
                    ))
                }
            };
            if f.count == 0 {
                return Err(bad(
                    "fields",
                    format!("field {axis} has count 0: it holds no value"),
                ));
            }
            let size = if wide { 8 } else { 4 };
            if (f.offset as usize) + size > self.point_step as usize {
                return Err(bad(
                    "fields",
                    format!(
                        "field {axis} at offset {} does not fit in point_step {}",
                        f.offset, self.point_step
                    ),
                ));
            }
            offsets[k] = (f.offset as usize, wide);
        }
        // An ambiguous layout is refused: a name given twice, or x, y, z
        // sharing bytes with each other or with another field.
        for axis in ["x", "y", "z"] {
            if self.fields.iter().filter(|f| f.name == axis).count() > 1 {
                return Err(bad(
                    "fields",
                    format!("field {axis} is given more than once (ambiguous layout)"),
                ));
            }
        }
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let (o, wide) = offsets[k];
            let end = o + if wide { 8 } else { 4 };
            for f in &self.fields {
                if f.name == *axis {
                    continue;
                }
                let size = datatype::size(f.datatype).unwrap_or(1) as u64;
                let f_end = u64::from(f.offset) + size * u64::from(f.count.max(1));
                if u64::from(f.offset) < end as u64 && (o as u64) < f_end {
                    return Err(bad(
                        "fields",
                        format!(
                            "field {axis} (bytes {o}..{end}) overlaps field {} (bytes {}..{f_end}) (ambiguous layout)",
                            f.name, f.offset
                        ),
                    ));
                }
            }
        }
        let step = self.point_step as usize;
        let row = self.row_step as usize;
        let width = self.width as usize;
        if step == 0 && width > 0 {
            return Err(bad("point_step", "0 with points in the cloud"));
        }
        if width.checked_mul(step).is_none_or(|b| b > row) {
            return Err(bad(
                "row_step",
                format!(
                    "{row} is shorter than width {} × point_step {step}",
                    self.width
                ),
            ));
        }
        let need = (self.height as usize).checked_mul(row);
        if need.is_none_or(|n| n > self.data.len()) {
            return Err(bad(
                "data",
                format!(
                    "{} bytes, fewer than height {} × row_step {row}",
                    self.data.len(),
                    self.height
                ),
            ));
        }
        Ok(XyzLayout {
            offsets,
            big: self.is_bigendian,
            step,
            row,
            width,
            height: self.height as usize,
        })
    }
}

/// Where x, y, z sit in a cloud's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct XyzLayout {
    /// (offset, float64?) of x, y, z.
    pub offsets: [(usize, bool); 3],
    /// Big-endian data.
    pub big: bool,
    /// Bytes per point.
    pub step: usize,
    /// Bytes per row.
    pub row: usize,
    /// Points per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

impl XyzLayout {
    /// Points in the cloud.
    #[must_use]
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the cloud is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bytes of point `i` (row-major).
    #[inline]
    #[must_use]
    pub fn point<'d>(&self, data: &'d [u8], i: usize) -> &'d [u8] {
        let (r, c) = (i / self.width.max(1), i % self.width.max(1));
        let at = r * self.row + c * self.step;
        &data[at..at + self.step]
    }

    #[inline]
    fn coord(&self, p: &[u8], k: usize) -> f64 {
        let (o, wide) = self.offsets[k];
        if wide {
            let b: [u8; 8] = p[o..o + 8].try_into().unwrap_or([0; 8]);
            if self.big {
                f64::from_be_bytes(b)
            } else {
                f64::from_le_bytes(b)
            }
        } else {
            let b: [u8; 4] = p[o..o + 4].try_into().unwrap_or([0; 4]);
            f64::from(if self.big {
                f32::from_be_bytes(b)
            } else {
                f32::from_le_bytes(b)
            })
        }
    }

    /// x, y, z of a point's bytes.
    #[inline]
    #[must_use]
    pub fn xyz(&self, p: &[u8]) -> [f64; 3] {
        [self.coord(p, 0), self.coord(p, 1), self.coord(p, 2)]
    }

    /// The bytes of row `r` holding points (`width × step`; the checks of
    /// [`PointCloud2::xyz`] keep it inside `data`).
    #[inline]
    fn row_points<'d>(&self, data: &'d [u8], r: usize) -> &'d [u8] {
        let at = r * self.row;
        &data[at..at + self.width * self.step]
    }

    /// Appends x, y, z of every point (row-major, as [`XyzLayout::point`]
    /// numbers them) to `out`: [`XyzLayout::xyz`] of each point, with one
    /// loop for the common layout (little-endian FLOAT32 x, y, z).
    pub fn decode_all(&self, data: &[u8], out: &mut Vec<[f64; 3]>) {
        if self.width == 0 {
            return;
        }
        out.reserve(self.len());
        let f32_le = !self.big && self.offsets.iter().all(|&(_, wide)| !wide);
        let [ox, oy, oz] = self.offsets.map(|(o, _)| o);
        let f32_at = |p: &[u8], o: usize| {
            f64::from(f32::from_le_bytes(p[o..o + 4].try_into().unwrap_or([0; 4])))
        };
        for r in 0..self.height {
            let row = self.row_points(data, r).chunks_exact(self.step);
            if f32_le {
                out.extend(row.map(|p| [f32_at(p, ox), f32_at(p, oy), f32_at(p, oz)]));
            } else {
                out.extend(row.map(|p| self.xyz(p)));
            }
        }
    }

    /// x, y, z of every point, row-major (as [`XyzLayout::point`] numbers
    /// them), decoded as they are read: nothing is allocated.
    #[must_use]
    pub fn points<'d>(&'d self, data: &'d [u8]) -> Points<'d> {
        Points {
            layout: self,
            data,
            f32_le: !self.big && self.offsets.iter().all(|&(_, wide)| !wide),
            at: 0,
            col: 0,
            left: self.len(),
        }
    }

    /// Byte ranges in `data` of the points `keep` marks, consecutive ones
    /// in a row merged (so a subset is copied in a few long pieces).
    #[must_use]
    pub fn kept_ranges(&self, keep: &[bool]) -> Vec<std::ops::Range<usize>> {
        let mut out = Vec::new();
        for r in 0..self.height {
            let row = &keep[r * self.width..(r + 1) * self.width];
            let base = r * self.row;
            let mut c = 0;
            while c < row.len() {
                if row[c] {
                    let start = c;
                    while c < row.len() && row[c] {
                        c += 1;
                    }
                    out.push(base + start * self.step..base + c * self.step);
                } else {
                    c += 1;
                }
            }
        }
        out
    }
}

/// The points of a cloud, decoded one by one ([`XyzLayout::points`]).
#[derive(Debug, Clone)]
pub struct Points<'d> {
    layout: &'d XyzLayout,
    data: &'d [u8],
    f32_le: bool,
    /// Byte offset of the next point.
    at: usize,
    /// Its column.
    col: usize,
    /// Points not yet returned.
    left: usize,
}

impl Iterator for Points<'_> {
    type Item = [f64; 3];

    #[inline]
    fn next(&mut self) -> Option<[f64; 3]> {
        let l = self.layout;
        if self.left == 0 {
            return None;
        }
        self.left -= 1;
        let p = &self.data[self.at..self.at + l.step];
        self.col += 1;
        if self.col == l.width {
            // The next row starts `row` bytes after this row's start.
            self.at += l.step + l.row - l.width * l.step;
            self.col = 0;
        } else {
            self.at += l.step;
        }
        Some(if self.f32_le {
            let f =
                |o: usize| f64::from(f32::from_le_bytes(p[o..o + 4].try_into().unwrap_or([0; 4])));
            [f(l.offsets[0].0), f(l.offsets[1].0), f(l.offsets[2].0)]
        } else {
            l.xyz(p)
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl ExactSizeIterator for Points<'_> {}

/// Encodes a `PointCloud2` of `kept` points (one row) taken from `src`'s
/// data in order: same header, fields, byte order and point step.
#[must_use]
pub fn encode_subset(
    src: &PointCloud2<'_>,
    layout: &XyzLayout,
    keep: &[bool],
    is_dense: bool,
) -> Vec<u8> {
    let kept = keep.iter().filter(|&&k| k).count();
    let total = kept * layout.step;
    let mut w = Writer::new(128 + total);
    src.header.write(&mut w);
    w.u32(1);
    w.u32(u32::try_from(kept).unwrap_or(u32::MAX));
    w.u32(u32::try_from(src.fields.len()).unwrap_or(u32::MAX));
    for f in &src.fields {
        w.string(f.name);
        w.u32(f.offset);
        w.u8(f.datatype);
        w.u32(f.count);
    }
    w.u8(u8::from(src.is_bigendian));
    w.u32(src.point_step);
    w.u32(u32::try_from(total).unwrap_or(u32::MAX));
    w.bytes_from(
        total,
        layout.kept_ranges(keep).into_iter().map(|r| &src.data[r]),
    );
    w.u8(u8::from(is_dense));
    w.finish()
}

/// `geometry_msgs/msg/TransformStamped`: the pose of `child_frame_id` in
/// `header.frame_id` (a point in the child frame is `rotation · p +
/// translation` in the parent frame).
#[derive(Debug, Clone, PartialEq)]
pub struct TransformStamped<'a> {
    /// Header (`frame_id`: the parent frame).
    pub header: Header<'a>,
    /// The child frame.
    pub child_frame_id: &'a str,
    /// Translation, m.
    pub translation: [f64; 3],
    /// Rotation as a quaternion `[x, y, z, w]`.
    pub rotation_xyzw: [f64; 4],
}

/// Smallest encoding of one `TransformStamped` (empty strings), bytes: a
/// bound for a corrupt count.
const TRANSFORM_MIN_BYTES: usize = 4 + 4 + 4 + 4 + 7 * 8;

/// `tf2_msgs/msg/TFMessage`: its transforms.
pub fn decode_tf_message(buf: &[u8]) -> Result<Vec<TransformStamped<'_>>, ReplayError> {
    let mut r = Reader::new(buf)?;
    let n = r.u32("transforms")? as usize;
    if n > buf.len() / TRANSFORM_MIN_BYTES {
        return Err(bad(
            "transforms",
            format!("{n} transforms in a {}-byte message", buf.len()),
        ));
    }
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let header = Header::read(&mut r)?;
        let child_frame_id = r.string("transforms[].child_frame_id")?;
        let mut translation = [0.0; 3];
        for v in &mut translation {
            *v = r.f64("transforms[].transform.translation")?;
        }
        let mut rotation_xyzw = [0.0; 4];
        for v in &mut rotation_xyzw {
            *v = r.f64("transforms[].transform.rotation")?;
        }
        out.push(TransformStamped {
            header,
            child_frame_id,
            translation,
            rotation_xyzw,
        });
    }
    Ok(out)
}

/// `tf2_msgs/msg/TFMessage`, encoded (little-endian).
#[must_use]
pub fn encode_tf_message(transforms: &[TransformStamped<'_>]) -> Vec<u8> {
    let mut w = Writer::new(64 + 128 * transforms.len());
    w.u32(u32::try_from(transforms.len()).unwrap_or(u32::MAX));
    for t in transforms {
        t.header.write(&mut w);
        w.string(t.child_frame_id);
        for v in t.translation.iter().chain(&t.rotation_xyzw) {
            w.f64(*v);
        }
    }
    w.finish()
}
