//! The scripts name test targets that exist: a `cargo test --test NAME` in scripts/ or .ci must
//! name a `[[test]]` of Cargo.toml. (tests/tests.rs is the one integration-test binary; a script
//! still naming one of its modules as a target, as crash-test.sh did with `crash`, fails only
//! when someone runs it.)

use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The `name`s of Cargo.toml's `[[test]]` tables.
fn test_targets() -> Vec<String> {
    let manifest = std::fs::read_to_string(Path::new(ROOT).join("Cargo.toml")).unwrap();
    let mut names = Vec::new();
    let mut in_test = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_test = line == "[[test]]";
        } else if let Some(value) = line.strip_prefix("name").filter(|_| in_test) {
            let value = value.trim_start().trim_start_matches('=').trim();
            names.push(value.trim_matches('"').to_string());
        }
    }
    assert!(!names.is_empty(), "no [[test]] in Cargo.toml");
    names
}

/// Every file below `dir` (relative to the repository).
fn files(dir: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![Path::new(ROOT).join(dir)];
    while let Some(p) = stack.pop() {
        if p.is_dir() {
            stack.extend(std::fs::read_dir(&p).unwrap().map(|e| e.unwrap().path()));
        } else {
            out.push(p);
        }
    }
    out
}

/// The targets each `cargo test` command line of `text` names with `--test NAME` or
/// `--test=NAME`, before a `--` (what follows it goes to the test binary). Lines continued with
/// a backslash are one command line.
fn named_targets(text: &str) -> Vec<String> {
    let joined = text.replace("\\\n", " ");
    let mut out = Vec::new();
    for line in joined.lines() {
        let Some((_, rest)) = line.split_once("cargo test") else {
            continue;
        };
        let mut words = rest.split_whitespace().take_while(|w| *w != "--");
        while let Some(w) = words.next() {
            if w == "--test" {
                out.extend(words.next().map(str::to_string));
            } else if let Some(name) = w.strip_prefix("--test=") {
                out.push(name.to_string());
            }
        }
    }
    out
}

#[test]
fn named_targets_reads_cargo_test_command_lines() {
    let script = "cargo test --release --test crash -- --nocapture --test x\n\
                  nice cargo test \\\n  --test=tests fuzz_db::\necho --test other\n";
    assert_eq!(named_targets(script), ["crash", "tests"]);
}

#[test]
fn scripts_name_only_test_targets_that_exist() {
    let targets = test_targets();
    let mut offences = Vec::new();
    for file in files("scripts").into_iter().chain(files(".ci")) {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        for name in named_targets(&text) {
            if !targets.contains(&name) {
                offences.push(format!("{}: --test {name}", file.display()));
            }
        }
    }
    assert!(
        offences.is_empty(),
        "cargo test targets that are not a [[test]] of Cargo.toml ({targets:?}):\n{}",
        offences.join("\n")
    );
}
