//! `read_gaze`: a recorded gaze file through the crate's own line parsers
//! (`gaze_lidar::gaze::Parser`, the one `gaze-lidar stream --input` uses),
//! with the CLI's rules for a recorded file: a malformed line is an error
//! naming the file, the line and the field; a UTF-8 byte-order mark or a
//! line that is not UTF-8 is refused.

use gaze_lidar::gaze::{Format, GazeError, LineError, Parser};

/// The named format (the names `gaze-lidar stream --format` takes, from
/// the library's one table), or a message listing the known ones.
pub fn format_of(name: &str) -> Result<Format, String> {
    name.parse().map_err(|e| format!("format: {e}"))
}

/// A gaze track as columns: times (s), azimuths (degrees, ISO 8855) and
/// whether each sample is usable (the parser's `GazeSample::usable`).
#[derive(Debug, Default, PartialEq)]
pub struct Track {
    pub t_s: Vec<f64>,
    pub gaze_deg: Vec<f64>,
    pub valid: Vec<bool>,
}

const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Parses the bytes of a recorded file (`origin` names it in errors).
pub fn parse(bytes: &[u8], format: Format, origin: &str) -> Result<Track, GazeError> {
    let mut parser = Parser::new(format);
    let mut track = Track::default();
    let fail = |line: usize, source: LineError| GazeError::Line {
        origin: origin.to_owned(),
        line,
        source,
    };
    if bytes.starts_with(UTF8_BOM) {
        return Err(fail(
            1,
            LineError::Bytes(
                "starts with a UTF-8 byte-order mark (bytes EF BB BF): send the data without a BOM"
                    .into(),
            ),
        ));
    }
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        let text = std::str::from_utf8(raw).map_err(|e| {
            fail(
                i + 1,
                LineError::Bytes(format!(
                    "not UTF-8 text (invalid byte 0x{:02X} at column {})",
                    raw[e.valid_up_to()],
                    e.valid_up_to() + 1
                )),
            )
        })?;
        if let Some(s) = parser.line(text).map_err(|e| fail(i + 1, e))? {
            track.t_s.push(s.t_s);
            track.gaze_deg.push(s.gaze_deg);
            track.valid.push(s.valid);
        }
    }
    Ok(track)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_and_errors_name_the_line() {
        let t = parse(
            b"t_s,gaze_deg,valid\n0.0,90,true\n0.01,91,false\n",
            Format::Csv,
            "x",
        )
        .unwrap();
        assert_eq!(t.t_s, vec![0.0, 0.01]);
        assert_eq!(t.valid, vec![true, false]);
        let e = parse(b"t_s,gaze_deg\n0.0,abc\n", Format::Csv, "x.csv").unwrap_err();
        assert!(e.to_string().starts_with("x.csv:2: "), "{e}");
        assert!(format_of("tobii")
            .unwrap_err()
            .contains("jsonl, csv, varjo, neon"));
    }
}
