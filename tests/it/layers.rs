//! Layers: which module may name which. Data flows one way: model ← gaze
//! (pure input) ← pipeline ← sim, replay, CLI, Python. `src/gaze/` must not reach the planners, the optimizer, the
//! checker or anything that drives it.

use std::path::Path;

/// Modules `gaze` may not name (outside comments).
const ABOVE: [&str; 7] = [
    "crate::planner",
    "crate::optimizer",
    "crate::checker",
    "crate::pipeline",
    "crate::sim",
    "crate::replay",
    "crate::cli",
];

/// `(file, line number, line)` of every code line in `dir` naming one of
/// `ABOVE`.
fn reaching_up(dir: &Path) -> Vec<(String, usize, String)> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(reaching_up(&path));
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if ABOVE.iter().any(|m| code.contains(m)) {
                found.push((path.display().to_string(), i + 1, line.to_owned()));
            }
        }
    }
    found
}

#[test]
fn gaze_names_nothing_above_it() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/gaze");
    let found = reaching_up(&dir);
    assert!(found.is_empty(), "src/gaze reaches up: {found:#?}");
}

#[test]
fn the_layer_check_sees_an_upward_import() {
    // The check itself can fail: a file naming the planner is reported.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("x.rs"),
        "// crate::planner in a comment is fine\nuse crate::planner::Mode;\n",
    )
    .unwrap();
    let found = reaching_up(dir.path());
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].1, 2);
}
