//! Keeps `specs/traceability.toml` honest: every named check, harness, test
//! and fuzz target exists; every listed harness is a Kani proof; every proof
//! harness backs a requirement.

use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

#[derive(Deserialize)]
struct Spec {
    requirement: Vec<Requirement>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Requirement {
    id: String,
    statement: String,
    checker: Vec<String>,
    kani: Vec<String>,
    tests: Vec<String>,
    fuzz: Vec<String>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn defines_fn(text: &str, name: &str) -> bool {
    text.contains(&format!("fn {name}(")) || text.contains(&format!("fn {name}<"))
}

/// Proof harness names in src: the `fn` following each `kani::proof` attribute.
fn proof_harnesses() -> BTreeSet<String> {
    let mut files = Vec::new();
    rust_files(&root().join("src"), &mut files);
    rust_files(&root().join("crates/core/src"), &mut files);
    let mut out = BTreeSet::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            if l.contains("kani::proof") && l.trim_start().starts_with("#[") {
                let next_fn = lines[i..].iter().find_map(|l| {
                    let t = l.trim_start();
                    t.strip_prefix("fn ")
                        .map(|r| r.split('(').next().unwrap_or("").to_owned())
                });
                out.insert(next_fn.expect("a fn follows every kani::proof"));
            }
        }
    }
    out
}

#[test]
fn traceability_table_is_honest() {
    let text = std::fs::read_to_string(root().join("specs/traceability.toml")).unwrap();
    let spec: Spec = toml::from_str(&text).unwrap();
    assert!(spec.requirement.len() >= 8, "at least 8 requirements");
    let harnesses = proof_harnesses();
    assert!(
        harnesses.len() >= 10,
        "at least 10 Kani harnesses, found {harnesses:?}"
    );
    let fuzz_manifest = std::fs::read_to_string(root().join("fuzz/Cargo.toml")).unwrap();
    let mut ids = BTreeSet::new();
    let mut traced_harnesses = BTreeSet::new();
    let mut fuzz_targets = BTreeSet::new();
    for r in &spec.requirement {
        assert!(ids.insert(r.id.clone()), "duplicate {}", r.id);
        assert!(r.id.starts_with("REQ-") && !r.statement.is_empty());
        assert!(
            !(r.kani.is_empty() && r.tests.is_empty()),
            "{}: backed by nothing",
            r.id
        );
        for item in r.checker.iter().chain(&r.tests) {
            let (file, func) = item
                .split_once("::")
                .unwrap_or_else(|| panic!("{}: '{item}' is not file::function", r.id));
            let body = std::fs::read_to_string(root().join(file))
                .unwrap_or_else(|_| panic!("{}: no file {file}", r.id));
            assert!(
                defines_fn(&body, func),
                "{}: {file} defines no fn {func}",
                r.id
            );
        }
        for h in &r.kani {
            assert!(
                harnesses.contains(h),
                "{}: {h} is not a kani::proof harness in src/",
                r.id
            );
            traced_harnesses.insert(h.clone());
        }
        for t in &r.fuzz {
            assert!(
                root().join(format!("fuzz/fuzz_targets/{t}.rs")).exists(),
                "{}: no fuzz target {t}",
                r.id
            );
            assert!(
                fuzz_manifest.contains(&format!("name = \"{t}\"")),
                "{}: {t} not in fuzz/Cargo.toml",
                r.id
            );
            assert!(
                root()
                    .join(format!("fuzz/seeds/{t}"))
                    .read_dir()
                    .is_ok_and(|mut d| d.next().is_some()),
                "{}: no seeds for {t}",
                r.id
            );
            fuzz_targets.insert(t.clone());
        }
    }
    let untraced: Vec<_> = harnesses.difference(&traced_harnesses).collect();
    assert!(
        untraced.is_empty(),
        "proof harnesses backing no requirement: {untraced:?}"
    );
    assert!(fuzz_targets.len() >= 4, "at least 4 fuzz targets traced");
}
