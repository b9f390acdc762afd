//! The layering of ARCHITECTURE.md, checked on the sources: a layer that starts to read the
//! database, run the solver or use the evaluation tooling where it must not fails here. (Cargo
//! already keeps SQLite and OpenCV out of the flow crate, and the `eval` feature keeps the
//! evaluation tooling out of a build of the tool alone.)

use std::path::Path;

/// Every `.rs` file below `dir` (relative to the crate root) with its text.
fn sources(dir: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join(dir)];
    while let Some(d) = stack.pop() {
        let path = d.as_path();
        if path.is_file() {
            out.push((
                d.display().to_string(),
                std::fs::read_to_string(path).unwrap(),
            ));
            continue;
        }
        for entry in std::fs::read_dir(path).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() || p.extension().is_some_and(|e| e == "rs") {
                stack.push(p);
            }
        }
    }
    assert!(!out.is_empty(), "no sources in {dir}");
    out
}

/// Fails naming each file of `dirs` that mentions one of `forbidden` outside comments.
fn forbid(dirs: &[&str], forbidden: &[&str], why: &str) {
    let mut offences = Vec::new();
    for dir in dirs {
        for (file, text) in sources(dir) {
            for (k, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap();
                for f in forbidden {
                    if code.contains(f) {
                        offences.push(format!("{file}:{}: {f}", k + 1));
                    }
                }
            }
        }
    }
    assert!(offences.is_empty(), "{why}:\n{}", offences.join("\n"));
}

#[test]
fn priors_geometry_and_scene_never_read_the_database() {
    forbid(
        &["src/priors", "src/geometry", "src/scene", "src/costs.rs"],
        &["Database", "rusqlite", "crate::selection", "crate::outputs"],
        "priors are pure functions of the loaded scene (ARCHITECTURE.md)",
    );
}

#[test]
fn the_colmap_layer_knows_nothing_above_it() {
    forbid(
        &["src/colmap"],
        &[
            "crate::scene",
            "crate::geometry",
            "crate::priors",
            "crate::costs",
            "crate::selection",
            "crate::outputs",
            "crate::eval",
            "opencv",
        ],
        "colmap is the bottom layer (ARCHITECTURE.md)",
    );
}

#[test]
fn outputs_only_format_what_the_plan_recorded() {
    forbid(
        &["src/outputs"],
        &["ParametricSolver", "solver::", "indicatif", "crate::eval"],
        "outputs draw and format; they do not re-run the solver or show progress",
    );
}

/// The library's layers that a prune runs (everything but the evaluation tooling).
const PRODUCT: &[&str] = &[
    "src/colmap",
    "src/scene",
    "src/geometry",
    "src/priors",
    "src/costs.rs",
    "src/selection",
    "src/outputs",
    "src/flow",
    "src/check",
];

#[test]
fn the_product_never_uses_the_evaluation_tooling() {
    forbid(
        PRODUCT,
        &["crate::eval", "vgsel_colmap::eval"],
        "the evaluation tooling is behind the `eval` feature and never used by a prune",
    );
}

#[test]
fn the_library_does_not_depend_on_the_argument_parser() {
    forbid(
        &[PRODUCT, &["src/eval", "src/lib.rs"]].concat(),
        &["clap"],
        "the libraries name their choices (vgsel_flow::named::Named); only src/cli parses the command line",
    );
}

/// `text` with its `//` comments blanked (line structure kept), so doc examples and prose that
/// name a path or a `fn` count for nothing.
fn code(text: &str) -> String {
    let lines = text.lines().map(|l| l.split("//").next().unwrap());
    lines.collect::<Vec<_>>().join("\n")
}

/// The use tree at the start of `s` (`a::b::{c, d::{e, f}}`, or a plain path `a::b::c`) as its
/// paths (`a::b::c`, `a::b::d::e`, `a::b::d::f`), and how many bytes of `s` it took.
fn use_tree(s: &str) -> (Vec<String>, usize) {
    let b = s.as_bytes();
    let is_ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'*';
    let mut i = 0;
    loop {
        while i < b.len() && is_ident(b[i]) {
            i += 1;
        }
        if !s[i..].starts_with("::") {
            return (vec![s[..i].to_string()], i);
        }
        i += 2;
        if b.get(i) == Some(&b'{') {
            let (prefix, mut out) = (&s[..i], Vec::new());
            i += 1;
            while i < b.len() && b[i] != b'}' {
                if b[i].is_ascii_whitespace() || b[i] == b',' {
                    i += 1;
                    continue;
                }
                let (inner, n) = use_tree(&s[i..]);
                out.extend(inner.into_iter().map(|p| format!("{prefix}{p}")));
                i += n.max(1);
            }
            return (out, i + 1);
        }
    }
}

/// The module `path` names from inside module `here` (`crate::a::b`), as its segments:
/// `crate::` from the root; `self::`, a child module's name and any other crate's path from
/// `here` (the latter then resolve to `here` itself); each `super::` one step up, but inside an
/// inline `mod tests { ... }` the first `super` is `here`.
fn absolute<'a>(here: &'a str, path: &'a str, in_inline_mod: bool) -> Vec<&'a str> {
    let mut full: Vec<&str> = here.split("::").collect();
    let mut rest: Vec<&str> = path.split("::").collect();
    let supers = rest.iter().take_while(|s| **s == "super").count();
    match rest[0] {
        "crate" => full.clear(),
        "self" => drop(rest.remove(0)),
        "super" => {
            let up = supers - in_inline_mod as usize;
            full.truncate(full.len().saturating_sub(up));
            rest.drain(..supers);
        }
        _ => {}
    }
    full.extend(rest);
    full
}

/// The file-level modules of one crate (`root` its `lib.rs` or `main.rs`, `dirs` its files) and
/// the edges `a -> b` where file `a` names a path of module `b` ([`absolute`]; `use` trees are
/// expanded, [`use_tree`]). `skip` leaves out files of other crates below `dirs`. Simplification:
/// everything after the first inline `mod x {` line of a file is taken to be inside it (in
/// `src/` that is `mod tests`, at the end).
fn import_graph(root: &str, dirs: &[&str], skip: &[&str]) -> Vec<(String, String)> {
    let base = format!("{}/", env!("CARGO_MANIFEST_DIR"));
    let root_dir = root.rsplit_once('/').unwrap().0;
    let files: Vec<(String, String)> = dirs.iter().flat_map(|d| sources(d)).collect();
    let files: Vec<(String, String)> = files
        .into_iter()
        .map(|(f, text)| (f.trim_start_matches(&base).to_string(), text))
        .filter(|(f, _)| !skip.iter().any(|s| f.starts_with(s)))
        .collect();
    // Module path of each file: src/a/mod.rs and src/a.rs are `crate::a`, the root is `crate`.
    let module = |file: &str| {
        let rel = file.trim_start_matches(root_dir).trim_end_matches(".rs");
        let rel = if file == root {
            ""
        } else {
            rel.trim_end_matches("/mod")
        };
        format!("crate{}", rel.replace('/', "::"))
    };
    let modules: Vec<(String, &str)> = files.iter().map(|(f, _)| (module(f), f.as_str())).collect();
    let mut edges = Vec::new();
    for (file, text) in &files {
        let (here, code) = (module(file), code(text));
        let inline_from = code
            .lines()
            .scan(0, |at, l| {
                Some((std::mem::replace(at, *at + l.len() + 1), l.trim()))
            })
            .find(|(_, l)| l.starts_with("mod ") && l.ends_with('{'))
            .map_or(code.len(), |(at, _)| at);
        let (b, mut i) = (code.as_bytes(), 0);
        while i < b.len() {
            let starts = (b[i].is_ascii_alphabetic() || b[i] == b'_')
                && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b"_:".contains(&b[i - 1])));
            if !starts {
                i += 1;
                continue;
            }
            let (paths, n) = use_tree(&code[i..]);
            for path in paths.iter().filter(|p| p.contains("::")) {
                let full = absolute(&here, path, i > inline_from);
                let target = (1..=full.len())
                    .rev()
                    .map(|k| full[..k].join("::"))
                    .find_map(|m| modules.iter().find(|(name, _)| *name == m));
                if let Some(&(_, to)) = target.filter(|(_, to)| to != file) {
                    let edge = (file.clone(), to.to_string());
                    if !edges.contains(&edge) {
                        edges.push(edge);
                    }
                }
            }
            i += n.max(1);
        }
    }
    edges
}

/// The import circles of `edges`: each group of files that all reach each other (a strongly
/// connected component of two or more files), sorted, with the edges that close it.
fn circles(edges: &[(String, String)]) -> Vec<(Vec<String>, Vec<String>)> {
    let reach = |from: &str| {
        let mut seen = vec![from.to_string()];
        let mut k = 0;
        while k < seen.len() {
            for (a, b) in edges {
                if *a == seen[k] && !seen.contains(b) {
                    seen.push(b.clone());
                }
            }
            k += 1;
        }
        seen
    };
    let mut out: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    for (a, _) in edges {
        let mut group: Vec<String> = reach(a)
            .into_iter()
            .filter(|b| reach(b).contains(a))
            .collect();
        group.sort();
        if group.len() > 1 && !out.iter().any(|(g, _)| *g == group) {
            let inside = edges
                .iter()
                .filter(|(a, b)| group.contains(a) && group.contains(b));
            out.push((
                group.clone(),
                inside.map(|(a, b)| format!("{a} -> {b}")).collect(),
            ));
        }
    }
    out
}

/// One home per concept: no two file-level modules of a crate name each other's paths, directly
/// or round a longer circle (`a` uses `b` uses `a`). A circle means a concept that both sides
/// need lives in one of them; move it where it belongs. Checked on the library, the binary
/// (`src/main.rs`, `src/cli`) and the flow crate (`src/flow`), from `crate::`, `super::`,
/// `self::` and child-module paths in the code (comments left out).
#[test]
fn no_import_circle() {
    let graphs = [
        import_graph(
            "src/lib.rs",
            &["src"],
            &["src/flow", "src/cli", "src/main.rs"],
        ),
        import_graph("src/main.rs", &["src/main.rs", "src/cli"], &[]),
        import_graph("src/flow/lib.rs", &["src/flow"], &[]),
    ];
    let mut offences = Vec::new();
    for edges in &graphs {
        for (files, inside) in circles(edges) {
            offences.push(format!(
                "{}\n    {}",
                files.join(" <-> "),
                inside.join("\n    ")
            ));
        }
    }
    assert!(
        offences.is_empty(),
        "import circles:\n{}",
        offences.join("\n")
    );
}

/// The phrase a doc comment starts a paragraph with when its function is one algorithm that
/// reads better whole than split, and so may be longer than [`MAX_FN_LINES`].
const READ_WHOLE: &str = "One algorithm, read whole:";

/// The most lines a function may take, from its `fn` line to its closing brace.
const MAX_FN_LINES: usize = 80;

/// Each function of `text` longer than `MAX_FN_LINES` whose doc comment lacks [`READ_WHOLE`], as
/// `(line, name, lines)`. The sources are rustfmt-formatted, so a function's closing brace is the
/// first later line that is `}` at the indentation of its `fn` line (a `;` there ends a bodiless
/// declaration).
fn long_functions(text: &str) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        let words: Vec<&str> = trimmed.split_whitespace().collect();
        let qualifiers = ["pub", "const", "async", "unsafe", "extern", "\"C\""];
        let Some(k) = words
            .iter()
            .position(|w| !qualifiers.contains(w) && !w.starts_with("pub("))
        else {
            continue;
        };
        if words[k] != "fn" || words.len() <= k + 1 || trimmed.ends_with('}') {
            continue;
        }
        let end = (start + 1..lines.len()).find(|&e| {
            let rest = lines[e].strip_prefix(indent).unwrap_or("");
            rest == "}" || (!rest.starts_with(' ') && rest.ends_with(';'))
        });
        let Some(end) = end.filter(|&e| lines[e].trim() == "}") else {
            continue;
        };
        let docs = lines[..start].iter().rev();
        let mut docs = docs
            .take_while(|l| l.trim_start().starts_with("///") || l.trim_start().starts_with("#["));
        if end - start + 1 > MAX_FN_LINES && !docs.any(|l| l.contains(READ_WHOLE)) {
            let name = words[k + 1].split(['(', '<']).next().unwrap().to_string();
            out.push((start + 1, name, end - start + 1));
        }
    }
    out
}

/// A function fits on a screen: at most [`MAX_FN_LINES`] lines, so each does one thing and its
/// steps have names. A function that is one algorithm, which splitting would only scatter (a
/// solver's core loop), says so in its doc comment with [`READ_WHOLE`] and is let be. Checked
/// on every file of `src/` (the flow crate and the binary too).
#[test]
fn functions_fit_on_a_screen() {
    let base = format!("{}/", env!("CARGO_MANIFEST_DIR"));
    let mut offences = Vec::new();
    for (file, text) in sources("src") {
        let file = file.trim_start_matches(&base);
        for (line, name, n) in long_functions(&text) {
            offences.push(format!("{file}:{line}: fn {name} has {n} lines"));
        }
    }
    offences.sort();
    assert!(
        offences.is_empty(),
        "functions over {MAX_FN_LINES} lines (split them into named steps, or say `{READ_WHOLE}` \
         in the doc comment of one algorithm that reads better whole):\n{}",
        offences.join("\n")
    );
}

/// The check itself: a long function is found (by its `fn` line and length, methods too), a
/// marked one, a short one and a bodiless declaration are not.
#[test]
fn long_functions_finds_a_long_unmarked_function() {
    let body = |n: usize| "        x += 1;\n".repeat(n);
    let text = format!(
        "impl A {{\n    pub(crate) fn long(\n        x: u32,\n    ) {{\n{}    }}\n\n    \
         /// {READ_WHOLE} the loop.\n    fn marked() {{\n{}    }}\n    fn short() {{ }}\n}}\n\
         trait T {{\n    fn declared(&self)\n        -> u32;\n}}\n",
        body(MAX_FN_LINES - 3),
        body(MAX_FN_LINES)
    );
    assert_eq!(
        long_functions(&text),
        [(2, "long".to_string(), MAX_FN_LINES + 1)]
    );
}

#[test]
fn stats_is_a_leaf() {
    forbid(
        &["src/stats.rs"],
        &["crate::", "nalgebra", "rusqlite", "opencv"],
        "stats holds what several layers share and uses none of them (ARCHITECTURE.md)",
    );
}
