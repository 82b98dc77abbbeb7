//! Text for messages: numbers in compact form (the core's [`Num`] and
//! [`Limit`]) and TOML errors as one line.

pub use gaze_lidar_core::text::{Limit, Num};

/// A TOML error as one line: `line:column: message` (1-based, the column
/// in characters) with the key it concerns (`in `limits.power_w_max``)
/// when toml knows it — never toml's multi-line snippet with a caret.
#[must_use]
pub fn toml_error(text: &str, e: &toml::de::Error) -> String {
    let message = toml_message(e);
    match e.span() {
        Some(span) => {
            let (line, column) = line_column(text, span.start);
            // toml names no key in "duplicate key": the span's does.
            let key = text
                .get(span)
                .and_then(|t| t.split('=').next())
                .map(|k| k.trim().trim_matches(|c| c == '[' || c == ']').trim())
                .filter(|k| message.starts_with("duplicate key") && !k.is_empty());
            match key {
                Some(k) => format!("{line}:{column}: {message} `{k}`"),
                None => format!("{line}:{column}: {message}"),
            }
        }
        None => message,
    }
}

/// toml's error as one line: the message and the key path (without the
/// input, toml's rendering has no snippet).
#[must_use]
pub fn toml_message(e: &toml::de::Error) -> String {
    let mut bare = e.clone();
    bare.set_input(None);
    bare.to_string()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// 1-based line and column (in characters) of byte `offset` in `text`
/// (clamped to its end).
#[must_use]
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let before = &text[..end];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Doc {
        a: Option<f64>,
        t: Option<Inner>,
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Inner {
        b: f64,
    }

    fn err(text: &str) -> String {
        toml_error(text, &toml::from_str::<Doc>(text).unwrap_err())
    }

    #[test]
    fn one_line_with_position_and_key() {
        let e = err("a = 1.0\n\na = = 3\n");
        assert!(e.starts_with("3:"), "{e}");
        assert!(
            !e.contains('\n') && !e.contains('^') && !e.contains(" | "),
            "{e}"
        );
        let e = err("[t]\nb = \"x\"\n");
        assert!(e.starts_with("2:5:"), "{e}");
        assert!(e.contains("t.b"), "{e}");
        let e = err("z = 1\n");
        assert!(e.starts_with("1:1:") && e.contains('z'), "{e}");
        // Characters, not bytes.
        assert_eq!(line_column("é = é = 1", 5), (1, 5));
        assert_eq!(line_column("a\nb", 99), (2, 2));
    }
}
