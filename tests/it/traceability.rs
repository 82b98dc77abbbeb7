//! Keeps `specs/traceability.toml` honest: every named check, harness, test
//! and fuzz target exists; every listed harness is a Kani proof; every proof
//! harness backs a requirement; every named test and harness exercises the
//! API its requirement is about (its body calls one of the requirement's
//! `api` names, directly or through a helper defined in the same file); and
//! every harness is gated so that plain `cargo kani` resolves.

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
    /// The functions (or `cli:SUBCOMMAND`) the requirement is about.
    api: Vec<String>,
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

// ---------------------------------------------------------------------------
// "The named test exercises the API": a small Rust tokenizer, brace matching
// and a call search through same-file helpers.

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Str(String),
    Punct(char),
}

/// Tokens of Rust source: identifiers, string literal contents and single
/// punctuation characters; comments, numbers, char literals and lifetimes
/// are dropped (enough to find calls and match braces).
fn tokenize(src: &str) -> Vec<Tok> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if ch == 'r' && matches!(c.get(i + 1), Some('"') | Some('#')) && {
            let mut j = i + 1;
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            c.get(j) == Some(&'"')
        } {
            // Raw string r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while c[j] == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1;
            let start = j;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (0..hashes).all(|k| c.get(j + 1 + k) == Some(&'#')) {
                    break;
                }
                j += 1;
            }
            out.push(Tok::Str(c[start..j.min(c.len())].iter().collect()));
            i = j + 1 + hashes;
        } else if ch == '"' {
            let mut j = i + 1;
            let mut text = String::new();
            while j < c.len() && c[j] != '"' {
                if c[j] == '\\' {
                    j += 1;
                }
                if j < c.len() {
                    text.push(c[j]);
                }
                j += 1;
            }
            out.push(Tok::Str(text));
            i = j + 1;
        } else if ch == '\'' {
            // Char literal ('x', '\n', '\u{..}') or lifetime ('a).
            if c.get(i + 1) == Some(&'\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
                while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                    i += 1;
                }
            }
        } else if ch.is_alphabetic() || ch == '_' {
            let mut j = i;
            while j < c.len() && (c[j].is_alphanumeric() || c[j] == '_') {
                j += 1;
            }
            out.push(Tok::Ident(c[i..j].iter().collect()));
            i = j;
        } else if ch.is_ascii_digit() {
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_' || c[i] == '.') {
                // Stop at a method call on a literal (`1.0.max(…)` is rare; `0..n` is not).
                if c[i] == '.' && c.get(i + 1) == Some(&'.') {
                    break;
                }
                i += 1;
            }
        } else {
            out.push(Tok::Punct(ch));
            i += 1;
        }
    }
    out
}

/// Index of the token matching the opener at `open` (`(`/`)` or `{`/`}`).
fn matching(toks: &[Tok], open: usize, (o, cl): (char, char)) -> Option<usize> {
    let mut depth = 0usize;
    for (k, t) in toks.iter().enumerate().skip(open) {
        if *t == Tok::Punct(o) {
            depth += 1;
        } else if *t == Tok::Punct(cl) {
            depth -= 1;
            if depth == 0 {
                return Some(k);
            }
        }
    }
    None
}

/// Every `fn NAME … { body }` of a file: name → body tokens (a test inside
/// `proptest!` is found the same way).
fn fn_bodies(toks: &[Tok]) -> Vec<(String, Vec<Tok>)> {
    let mut out = Vec::new();
    let mut k = 0;
    while k + 1 < toks.len() {
        if toks[k] == Tok::Ident("fn".into()) {
            if let Tok::Ident(name) = &toks[k + 1] {
                // The parameter list, then the body's opening brace.
                let Some(p) = (k + 2..toks.len()).find(|&j| toks[j] == Tok::Punct('(')) else {
                    break;
                };
                let Some(pe) = matching(toks, p, ('(', ')')) else {
                    break;
                };
                let next = (pe + 1..toks.len())
                    .find(|&j| matches!(toks[j], Tok::Punct('{') | Tok::Punct(';')));
                if let Some(b) = next.filter(|&j| toks[j] == Tok::Punct('{')) {
                    if let Some(be) = matching(toks, b, ('{', '}')) {
                        out.push((name.clone(), toks[b + 1..be].to_vec()));
                    }
                }
            }
        }
        k += 1;
    }
    out
}

/// Names called in a body: `name(`, `name::<…>(` and `name!(` (macros),
/// each also as `module::name` when called through its module path.
fn calls(body: &[Tok]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (k, t) in body.iter().enumerate() {
        if let Tok::Ident(name) = t {
            let next = body.get(k + 1);
            let turbofish = next == Some(&Tok::Punct(':'))
                && body.get(k + 2) == Some(&Tok::Punct(':'))
                && body.get(k + 3) == Some(&Tok::Punct('<'));
            if next == Some(&Tok::Punct('(')) || next == Some(&Tok::Punct('!')) || turbofish {
                out.insert(name.clone());
                // Also as `module::name` (an api entry may be qualified).
                if k >= 3 && body[k - 1] == Tok::Punct(':') && body[k - 2] == Tok::Punct(':') {
                    if let Tok::Ident(module) = &body[k - 3] {
                        out.insert(format!("{module}::{name}"));
                    }
                }
            }
        }
    }
    out
}

/// Whether function `func` of the source `src` exercises one of `api`:
/// calls one of the names (or, for `cli:SUB`, passes the string literal
/// `SUB`), directly or through functions defined in the same source.
/// `None` when `src` defines no such function.
fn exercises(src: &str, func: &str, api: &[String]) -> Option<bool> {
    let toks = tokenize(src);
    let bodies = fn_bodies(&toks);
    let body_of = |name: &str| -> Vec<&Vec<Tok>> {
        bodies
            .iter()
            .filter(|(n, _)| n == name)
            .map(|(_, b)| b)
            .collect()
    };
    if body_of(func).is_empty() {
        return None;
    }
    let mut seen = BTreeSet::new();
    let mut todo = vec![func.to_owned()];
    while let Some(f) = todo.pop() {
        if !seen.insert(f.clone()) {
            continue;
        }
        for body in body_of(&f) {
            let called = calls(body);
            for a in api {
                let hit = match a.strip_prefix("cli:") {
                    Some(sub) => body.iter().any(|t| *t == Tok::Str(sub.to_owned())),
                    None => called.contains(a),
                };
                if hit {
                    return Some(true);
                }
            }
            todo.extend(called.into_iter().filter(|c| !body_of(c).is_empty()));
        }
    }
    Some(false)
}

#[test]
fn named_tests_exercise_their_requirements_api() {
    let text = std::fs::read_to_string(root().join("specs/traceability.toml")).unwrap();
    let spec: Spec = toml::from_str(&text).unwrap();
    let mut harness_src = Vec::new();
    rust_files(&root().join("src"), &mut harness_src);
    rust_files(&root().join("crates/core/src"), &mut harness_src);
    let harness_src: Vec<String> = harness_src
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap())
        .collect();
    let mut failures = Vec::new();
    for r in &spec.requirement {
        assert!(!r.api.is_empty(), "{}: no api named", r.id);
        for item in &r.tests {
            let (file, func) = item.split_once("::").unwrap();
            let src = std::fs::read_to_string(root().join(file)).unwrap();
            match exercises(&src, func, &r.api) {
                Some(true) => {}
                Some(false) => failures.push(format!("{}: {item} calls none of {:?}", r.id, r.api)),
                None => failures.push(format!("{}: {item}: no fn body found", r.id)),
            }
        }
        for h in &r.kani {
            let found: Vec<bool> = harness_src
                .iter()
                .filter_map(|src| exercises(src, h, &r.api))
                .collect();
            if !found.contains(&true) {
                failures.push(format!("{}: harness {h} calls none of {:?}", r.id, r.api));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The matcher can fail: a test that does not call the API (only mentions
/// it in a comment, a string or a helper it never calls) is caught; direct
/// calls, calls through same-file helpers, method calls, turbofish calls
/// and `cli:` subcommands are found.
#[test]
fn api_matcher_rejects_tests_that_do_not_call_the_api() {
    let src = r####"
        fn helper(p: &Profile) -> bool {
            // certify(p) would be nice
            check_table(&table_of(p)).is_empty()
        }
        fn unused_helper() { certify(p()); }
        fn table_of(p: &Profile) -> Table { Table::new('{', "}{") }
        #[test]
        fn only_mentions() {
            let s = "certify(x)"; /* certify(y) */
            let certify_count = 3;
            assert_eq!(s.len(), certify_count);
        }
        #[test]
        fn via_helper() { assert!(helper(&p())); }
        #[test]
        fn method_call() { let v = x.certify(); }
        #[test]
        fn turbofish() { let v = certify::<u8>(x); }
        #[test]
        fn qualified() { sim::run(&c); }
        #[test]
        fn raw_string_brace() { let s = r#"{"#; certify(s); }
        #[test]
        fn cli() { run(&["check", "--preset", "paper"], None); }
        proptest! {
            #[test]
            fn prop(x in 0u8..4) { prop_assert!(x < 4); }
        }
    "####;
    let api = |names: &[&str]| names.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(
        exercises(src, "only_mentions", &api(&["certify"])),
        Some(false)
    );
    assert_eq!(
        exercises(src, "via_helper", &api(&["certify"])),
        Some(false)
    );
    assert_eq!(
        exercises(src, "via_helper", &api(&["check_table"])),
        Some(true)
    );
    assert_eq!(
        exercises(src, "method_call", &api(&["certify"])),
        Some(true)
    );
    assert_eq!(exercises(src, "turbofish", &api(&["certify"])), Some(true));
    assert_eq!(
        exercises(src, "raw_string_brace", &api(&["certify"])),
        Some(true)
    );
    assert_eq!(exercises(src, "cli", &api(&["cli:check"])), Some(true));
    assert_eq!(exercises(src, "qualified", &api(&["sim::run"])), Some(true));
    assert_eq!(exercises(src, "cli", &api(&["sim::run"])), Some(false));
    assert_eq!(exercises(src, "cli", &api(&["cli:profile"])), Some(false));
    assert_eq!(exercises(src, "prop", &api(&["certify"])), Some(false));
    assert_eq!(exercises(src, "missing", &api(&["certify"])), None);
}

/// Messages of the `cover!(cond, "msg")` calls and of the
/// `assert_covered(&["msg", …])` calls in a body.
fn covers(body: &[Tok]) -> (BTreeSet<String>, BTreeSet<String>) {
    let (mut covered, mut asserted) = (BTreeSet::new(), BTreeSet::new());
    for k in 0..body.len() {
        let Tok::Ident(name) = &body[k] else { continue };
        let open = if name == "cover" && body.get(k + 1) == Some(&Tok::Punct('!')) {
            k + 2
        } else if name == "assert_covered" {
            k + 1
        } else {
            continue;
        };
        let Some(end) = matching(body, open, ('(', ')')) else {
            continue;
        };
        let mut strs = body[open..end].iter().filter_map(|t| match t {
            Tok::Str(s) => Some(s.clone()),
            _ => None,
        });
        if name == "cover" {
            covered.extend(strs.next_back());
        } else {
            asserted.extend(strs);
        }
    }
    (covered, asserted)
}

/// Kani gating (specs/verification.md): plain `cargo kani -p gaze-lidar-core`
/// builds the library without dev-dependencies, so a harness may name
/// bolero only through `for_all!` (bolero in its `cfg(not(kani))` branch);
/// every harness is `#[cfg_attr(kani, kani::proof)]` on the test itself; every
/// harness has a `cover!` and asserts under `cargo test` that each of its
/// covers was hit (no harness passes vacuously).
#[test]
fn kani_harnesses_are_gated_and_covered() {
    let mut files = Vec::new();
    rust_files(&root().join("src"), &mut files);
    rust_files(&root().join("crates/core/src"), &mut files);
    let mut problems = Vec::new();
    let mut harnesses = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let rel = f.strip_prefix(root()).unwrap().display().to_string();
        if !rel.ends_with("verification.rs") && text.contains("bolero::") {
            problems.push(format!(
                "{rel}: names bolero outside for_all! (breaks plain cargo kani)"
            ));
        }
        if !text.contains("kani::proof") {
            continue;
        }
        let lines: Vec<&str> = text.lines().collect();
        let bodies = fn_bodies(&tokenize(&text));
        for (i, l) in lines.iter().enumerate() {
            if !l.contains("kani::proof") || !l.trim_start().starts_with("#[") {
                continue;
            }
            harnesses += 1;
            if !l.trim_start().starts_with("#[cfg_attr(kani, kani::proof") {
                problems.push(format!(
                    "{rel}:{}: not #[cfg_attr(kani, kani::proof…)]",
                    i + 1
                ));
            }
            let attrs: Vec<&str> = lines[i..]
                .iter()
                .take_while(|l| !l.trim_start().starts_with("fn "))
                .copied()
                .collect();
            if !attrs
                .iter()
                .any(|a| a.contains("#[cfg_attr(not(kani), test)]"))
            {
                problems.push(format!(
                    "{rel}:{}: harness is not a test under cargo test",
                    i + 1
                ));
            }
            let Some(name) = lines[i..].iter().find_map(|l| {
                l.trim_start()
                    .strip_prefix("fn ")
                    .map(|r| r.split('(').next().unwrap_or("").to_owned())
            }) else {
                problems.push(format!("{rel}:{}: no fn after kani::proof", i + 1));
                continue;
            };
            let Some((_, body)) = bodies.iter().find(|(n, _)| *n == name) else {
                problems.push(format!("{rel}: {name}: no body"));
                continue;
            };
            let (covered, asserted) = covers(body);
            if covered.is_empty() {
                problems.push(format!("{rel}: {name}: no cover! (vacuity unchecked)"));
            }
            for m in covered.difference(&asserted) {
                problems.push(format!("{rel}: {name}: cover \"{m}\" never asserted hit"));
            }
        }
    }
    assert!(harnesses >= 10, "found only {harnesses} harnesses");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The gating check can fail: a cover that is never asserted is found.
#[test]
fn cover_check_finds_unasserted_covers() {
    let src = r#"
        fn h() {
            for_all!(u8, |x| { cover!(x > 3, "big"); cover!(x == 0, "zero"); });
            #[cfg(not(kani))]
            crate::verification::assert_covered(&["big"]);
        }
    "#;
    let bodies = fn_bodies(&tokenize(src));
    let (covered, asserted) = covers(&bodies[0].1);
    let missing: Vec<_> = covered.difference(&asserted).cloned().collect();
    assert_eq!(missing, vec!["zero".to_owned()]);
}

// ---------------------------------------------------------------------------
// Every requirement ID cited anywhere exists, and a harness cites the
// requirements that list it.

/// `REQ-LETTERS-DIGITS` IDs in `text`, in order.
fn cited_req_ids(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("REQ-") {
        let after = &rest[i + 4..];
        let letters = after
            .find(|c: char| !c.is_ascii_uppercase())
            .unwrap_or(after.len());
        let tail = &after[letters..];
        if letters > 0 && tail.starts_with('-') {
            let digits = tail[1..]
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(tail.len() - 1);
            if digits > 0 {
                out.push(format!(
                    "REQ-{}-{}",
                    &after[..letters],
                    &tail[1..1 + digits]
                ));
            }
        }
        rest = &rest[i + 4..];
    }
    out
}

/// Source, script and documentation files of the repository (no build
/// output, no fuzz corpora, not the table itself).
fn cited_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if !(name.starts_with('.')
                || [
                    "target",
                    "corpus",
                    "artifacts",
                    "node_modules",
                    "__pycache__",
                ]
                .contains(&name.as_str()))
            {
                cited_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| {
            ["rs", "py", "pyi", "md", "sh", "toml", "tex"]
                .iter()
                .any(|e| x == *e)
        }) && p != root().join("specs/traceability.toml")
            && name != "Cargo.lock"
        {
            out.push(p);
        }
    }
}

#[test]
fn every_cited_requirement_exists() {
    let text = std::fs::read_to_string(root().join("specs/traceability.toml")).unwrap();
    let spec: Spec = toml::from_str(&text).unwrap();
    let ids: BTreeSet<&str> = spec.requirement.iter().map(|r| r.id.as_str()).collect();
    let mut files = Vec::new();
    cited_files(&root(), &mut files);
    let mut cited = 0;
    let mut missing = Vec::new();
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        for (n, line) in text.lines().enumerate() {
            for id in cited_req_ids(line) {
                cited += 1;
                if !ids.contains(id.as_str()) {
                    let rel = f.strip_prefix(root()).unwrap().display().to_string();
                    missing.push(format!("{rel}:{}: {id}", n + 1));
                }
            }
        }
    }
    assert!(
        cited >= 20,
        "only {cited} citations found: the scan is broken"
    );
    assert!(
        missing.is_empty(),
        "cited but not in specs/traceability.toml:\n{}",
        missing.join("\n")
    );
}

/// A proof harness's doc comment cites requirements; each of them must list
/// the harness in its `kani` entry (so the comment and the table agree).
#[test]
fn harness_doc_comments_cite_the_requirements_that_list_them() {
    let text = std::fs::read_to_string(root().join("specs/traceability.toml")).unwrap();
    let spec: Spec = toml::from_str(&text).unwrap();
    let mut files = Vec::new();
    rust_files(&root().join("src"), &mut files);
    rust_files(&root().join("crates/core/src"), &mut files);
    let mut problems = Vec::new();
    let mut checked = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            if !(l.contains("kani::proof") && l.trim_start().starts_with("#[")) {
                continue;
            }
            let name = lines[i..]
                .iter()
                .find_map(|l| {
                    l.trim_start()
                        .strip_prefix("fn ")
                        .map(|r| r.split('(').next().unwrap_or("").to_owned())
                })
                .unwrap();
            // The doc comment: the `///` lines right above the attributes.
            let doc: String = lines[..i]
                .iter()
                .rev()
                .take_while(|l| l.trim_start().starts_with("///"))
                .copied()
                .collect::<Vec<_>>()
                .join("\n");
            let cited = cited_req_ids(&doc);
            if cited.is_empty() {
                problems.push(format!("{name}: doc comment cites no requirement"));
            }
            for id in cited {
                checked += 1;
                match spec.requirement.iter().find(|r| r.id == id) {
                    Some(r) if r.kani.contains(&name) => {}
                    Some(_) => problems.push(format!("{name}: cites {id}, which does not list it")),
                    None => problems.push(format!("{name}: cites {id}, which does not exist")),
                }
            }
        }
    }
    assert!(checked >= 10, "{checked}");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The ID scanner can fail: it finds IDs in prose and code, and an ID that
/// is not in the table is reported (built here so that this file cites none).
#[test]
fn req_id_scanner_finds_ids() {
    let bogus = format!("REQ-{}-{}", "ZZ", 9);
    let text = format!("/// {bogus}: text; see REQ-FW-3, (REQ-IN-1) and REQ-x-1, REQ-AB-, REQ-");
    assert_eq!(
        cited_req_ids(&text),
        vec![bogus, "REQ-FW-3".into(), "REQ-IN-1".into()]
    );
}

/// The backticked names of a Markdown table row's cell that look like paths
/// (contain `/` or end in a file extension we keep in the tree).
fn path_like(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .filter(|t| !t.contains(' ') && !t.contains("::"))
        .filter(|t| {
            t.contains('/')
                || [".rs", ".md", ".toml", ".py", ".sh"]
                    .iter()
                    .any(|e| t.ends_with(e))
        })
        .map(str::to_owned)
        .collect()
}

/// Every path the README's layout table names, checked against the tree: the
/// folders of the first column from the repository root, the names inside a
/// row's description from that row's folder (or its `src/`) or the root.
/// Returns the names that resolve nowhere.
fn missing_layout_paths(readme: &str, root: &Path) -> Vec<String> {
    let section = readme
        .split("\n## Layout")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .unwrap_or("");
    let mut missing = Vec::new();
    for row in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = row.split(" | ").collect();
        let folders = path_like(cells[0]);
        for folder in &folders {
            if !root.join(folder).exists() {
                missing.push(folder.clone());
            }
        }
        for name in cells.iter().skip(1).flat_map(|c| path_like(c)) {
            let found = std::iter::once(root.to_path_buf())
                .chain(folders.iter().flat_map(|f| {
                    let base = if f.ends_with('/') {
                        root.join(f)
                    } else {
                        root.join(f).parent().unwrap_or(root).to_path_buf()
                    };
                    [base.clone(), base.join("src")]
                }))
                .any(|b| b.join(&name).exists());
            if !found {
                missing.push(name);
            }
        }
    }
    missing
}

#[test]
fn readme_layout_names_only_paths_that_exist() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(
        readme.contains("\n## Layout"),
        "README has a Layout section"
    );
    let missing = missing_layout_paths(&readme, &root());
    assert!(
        missing.is_empty(),
        "README's layout table names paths that do not exist: {missing:?}"
    );
}

#[test]
fn layout_check_flags_a_path_that_does_not_exist() {
    let table = "intro\n## Layout\n\n| folder | what |\n|---|---|\n\
                 | `src/sim/` | the simulator: `plots.rs`, `nowhere/gone.rs` |\n\
                 | `src/not_a_folder/` | nothing |\n\n## Next\n| `src/zzz/` | outside |\n";
    assert_eq!(
        missing_layout_paths(table, &root()),
        vec!["nowhere/gone.rs".to_owned(), "src/not_a_folder/".to_owned()]
    );
}

/// Every text file of the repository the citation check reads (sources,
/// specs, docs, scripts), skipping build output and virtual environments.
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() {
            if !name.starts_with('.') && !["target", "node_modules", "venv"].contains(&name) {
                text_files(&p, out);
            }
        } else if ["rs", "py", "pyi", "md", "toml", "sh"]
            .iter()
            .any(|x| p.extension().is_some_and(|e| e == *x))
        {
            out.push(p);
        }
    }
}

/// The documents a text cites: tokens ending in `.md` that name a project
/// document — an upper-case file name (`README.md`, `CHANGELOG.md`) or a
/// path under `specs/` or `docs/`, or any path leaving the repository
/// (`../`). Output file names in examples (`report.md`) are not citations.
fn cited_documents(text: &str) -> Vec<String> {
    let ok = |c: char| c.is_ascii_alphanumeric() || "_./-".contains(c);
    let mut out = Vec::new();
    for (at, _) in text.match_indices(".md") {
        if text[at + 3..]
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphanumeric())
        {
            continue;
        }
        let start = text[..at]
            .char_indices()
            .rev()
            .take_while(|&(_, c)| ok(c))
            .last()
            .map_or(at, |(i, _)| i);
        let token = &text[start..at + 3];
        if text[..start].ends_with("//") || token.contains("//") {
            continue;
        }
        let base = token.rsplit('/').next().unwrap_or(token);
        let stem = &base[..base.len() - 3];
        let upper = !stem.is_empty()
            && stem
                .chars()
                .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit());
        if upper
            || token.starts_with("specs/")
            || token.starts_with("docs/")
            || token.starts_with("../")
        {
            out.push(token.to_owned());
        }
    }
    out
}

#[test]
fn every_cited_document_exists_in_the_repository() {
    let root = root();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    let mut missing = Vec::new();
    for f in files {
        let Ok(text) = std::fs::read_to_string(&f) else {
            continue;
        };
        let dir = f.parent().unwrap_or(&root);
        for cited in cited_documents(&text) {
            let inside = |p: PathBuf| {
                p.canonicalize()
                    .is_ok_and(|c| c.starts_with(root.canonicalize().unwrap()))
            };
            let rooted = cited.trim_start_matches('/');
            let found = inside(root.join(rooted)) || inside(dir.join(&cited));
            if !found {
                let rel = f.strip_prefix(&root).unwrap_or(&f).display().to_string();
                missing.push(format!("{rel}: {cited}"));
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "documents cited but not in the repository: {missing:#?}"
    );
}

#[test]
fn citation_scanner_finds_design_style_citations() {
    // Built at run time so that this file does not cite what it tests.
    let (design, heads) = (["DESIGN", "md"].join("."), ["HEADS", "md"].join("."));
    let text = format!(
        "see {design} §5, `../shared/{heads}` and specs/eye_safety.md; \
         writes report.md; https://github.com/x/y/blob/main/CONTRIBUTING.md"
    );
    assert_eq!(
        cited_documents(&text),
        vec![
            design,
            format!("../shared/{heads}"),
            "specs/eye_safety.md".to_owned()
        ]
    );
}

/// Labels of past work in a text, each as `line: label`: issue numbers
/// (the word, an optional `s`, then a number after spaces, `#` or `-`; or a
/// bare `#` and a number after a space or `(`, except a cited pull request),
/// review rounds (the word and a number that is not a decimal), work
/// sessions and reviewers' numbered handles. With `strict` (specs and the
/// README) also dates (`YYYY-MM-DD`) and commit hashes (a backticked run of
/// 7–12 hex digits with a letter and a digit, or a hash after `commit`).
/// History goes in `CHANGELOG.md`; everything else states what is.
fn history_labels(text: &str, strict: bool) -> Vec<String> {
    let lower = text.to_ascii_lowercase();
    let b = lower.as_bytes();
    let alnum = |i: usize| b[i].is_ascii_alphanumeric();
    let digits_from = |mut i: usize, sep: &[u8]| -> Option<usize> {
        while i < b.len() && sep.contains(&b[i]) {
            i += 1;
        }
        let start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        (i > start).then_some(i)
    };
    let hex_run = |i: usize| {
        let n = b[i..]
            .iter()
            .take_while(|c| c.is_ascii_digit() || (b'a'..=b'f').contains(c))
            .count();
        let run = &b[i..i + n];
        (run.iter().any(u8::is_ascii_digit) && run.iter().any(u8::is_ascii_alphabetic)).then_some(n)
    };
    // The label starting at byte `i`, as its end.
    let label_at = |i: usize| -> Option<usize> {
        let after_word = i == 0 || !alnum(i - 1);
        let at = |w: &str| after_word && b[i..].starts_with(w.as_bytes());
        if at("issue") {
            let j = i + 5 + usize::from(b.get(i + 5) == Some(&b's'));
            return digits_from(j, b" #-");
        }
        if at("round") || at("session") {
            let j = i + if b[i] == b'r' { 5 } else { 7 };
            let end = digits_from(j, b" _-")?;
            let decimal =
                b.get(end) == Some(&b'.') && b.get(end + 1).is_some_and(u8::is_ascii_digit);
            return (!decimal).then_some(end);
        }
        if at("breaker") {
            return digits_from(i + 7, b"");
        }
        if b[i] == b'#' && (i == 0 || b" \t\n(".contains(&b[i - 1])) {
            let end = digits_from(i + 1, b"")?;
            let cited_pr = b[..i].ends_with(b"pr ");
            let longer_word = end < b.len() && alnum(end);
            return (!cited_pr && !longer_word).then_some(end);
        }
        if !strict {
            return None;
        }
        if at("20") && i + 10 <= b.len() {
            let shape = b[i..i + 10].iter().enumerate().all(|(k, c)| {
                if k == 4 || k == 7 {
                    *c == b'-'
                } else {
                    c.is_ascii_digit()
                }
            });
            let ends = !(i + 10 < b.len() && b[i + 10].is_ascii_digit());
            return (shape && ends).then_some(i + 10);
        }
        if b[i] == b'`' && i + 1 < b.len() {
            let n = hex_run(i + 1)?;
            return ((7..=12).contains(&n) && b.get(i + 1 + n) == Some(&b'`')).then_some(i + n + 2);
        }
        if at("commit ") {
            let n = hex_run(i + 7)?;
            return (n >= 7).then_some(i + 7 + n);
        }
        None
    };
    let mut found: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match label_at(i) {
            Some(end) => {
                found.push((i, end));
                i = end;
            }
            None => i += 1,
        }
    }
    found
        .into_iter()
        .map(|(s, e)| format!("{}: {}", text[..s].matches('\n').count() + 1, &text[s..e]))
        .collect()
}

#[test]
fn specs_readme_and_sources_state_what_is_without_history_labels() {
    let root = root();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    let mut labelled = Vec::new();
    for f in files {
        let rel = f.strip_prefix(&root).unwrap_or(&f).to_path_buf();
        if rel == Path::new("CHANGELOG.md") {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&f) else {
            continue;
        };
        let strict = rel == Path::new("README.md") || rel.starts_with("specs");
        for label in history_labels(&text, strict) {
            labelled.push(format!("{}:{label}", rel.display()));
        }
    }
    assert!(
        labelled.is_empty(),
        "history labels outside CHANGELOG.md (state what is instead): {labelled:#?}"
    );
}

#[test]
fn history_scanner_finds_every_kind_of_label() {
    // The labels are written with a `~` inside, removed at run time, so that
    // this file carries none of the labels it tests.
    let unmark = |s: &str| s.replace('~', "");
    let text = unmark(
        "A (Iss~ue 21) b; iss~ues #~4; iss~ue-29\nfixed in (#~12), hostile_rou~nd3, \
         Rou~nd 2, sess~ion 7, break~er4\n20~26-11-22 at `b14~eeb0`, com~mit 5a~59f87.\n",
    );
    let expected = [
        "1: Iss~ue 21",
        "1: iss~ues #~4",
        "1: iss~ue-29",
        "2: #~12",
        "2: rou~nd3",
        "2: Rou~nd 2",
        "2: sess~ion 7",
        "2: break~er4",
        "3: 20~26-11-22",
        "3: `b14~eeb0`",
        "3: com~mit 5a~59f87",
    ];
    assert_eq!(history_labels(&text, true), expected.map(unmark).to_vec());
    assert_eq!(history_labels(&text, false).len(), 8);
    // What is not a label: a decimal after the word, a cited pull request,
    // an attribute, a Markdown heading, a family member in backticks, a
    // word that only contains one of the keywords.
    let clean = unmark(
        "one rou~nd 8.91094 in 4 ms; PR #~518; #[test]\n## Layout\n\
         the `#~48` member; roundabout 3; tissue 5; at 1e-9 ",
    );
    assert!(
        history_labels(&clean, true).is_empty(),
        "{:?}",
        history_labels(&clean, true)
    );
}
