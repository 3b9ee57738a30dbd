//! The library never names a command-line flag (docs/api.md, `error.rs`): its messages say the
//! condition in library terms and the CLI adds its flag hints (`robodyn-cli/src/hint.rs`). This
//! test reads every string literal of the library's sources and fails on one containing
//! `--` followed by a letter.

use std::path::{Path, PathBuf};

/// Documented exceptions (file, literal): none.
const ALLOWED: &[(&str, &str)] = &[];

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The string literals of Rust source `s` with their 1-based lines: ordinary, byte and raw
/// strings; comments, character literals and lifetimes skipped.
fn literals(s: &str) -> Vec<(usize, String)> {
    let b = s.as_bytes();
    let line = |i: usize| s[..i].matches('\n').count() + 1;
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let rest = &s[i..];
        let ident_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").expect("unclosed block comment") + 2;
        } else if !ident_before && (rest.starts_with("r\"") || rest.starts_with("r#")) {
            let hashes = rest[1..].bytes().take_while(|&c| c == b'#').count();
            if rest.as_bytes().get(1 + hashes) != Some(&b'"') {
                i += 1;
                continue;
            }
            let open = 2 + hashes;
            let close = format!("\"{}", "#".repeat(hashes));
            let end = rest[open..].find(&close).expect("unclosed raw string");
            out.push((line(i), rest[open..open + end].to_string()));
            i += open + end + close.len();
        } else if b[i] == b'\'' {
            // a character literal ('x', '\n', '\''), else a lifetime or label
            let mut j = i + 1;
            if b.get(j) == Some(&b'\\') {
                j += 2;
                while j < b.len() && b[j] != b'\'' {
                    j += 1;
                }
                i = j + 1;
            } else {
                let c = rest[1..].chars().next().map_or(1, char::len_utf8);
                j += c;
                i = if b.get(j) == Some(&b'\'') {
                    j + 1
                } else {
                    i + 1
                };
            }
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            out.push((line(i), s[i + 1..j].to_string()));
            i = j + 1;
        } else {
            i += 1;
        }
    }
    out
}

fn names_a_flag(t: &str) -> bool {
    t.as_bytes()
        .windows(3)
        .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_lowercase())
}

#[test]
fn no_library_string_names_a_cli_flag() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    files.sort();
    assert!(files.len() > 50, "the library's sources not found");
    let mut found = Vec::new();
    let mut count = 0;
    for f in &files {
        let rel = f.strip_prefix(root).unwrap().display().to_string();
        let text = std::fs::read_to_string(f).unwrap();
        for (line, lit) in literals(&text) {
            count += 1;
            if names_a_flag(&lit) && !ALLOWED.contains(&(rel.as_str(), lit.as_str())) {
                found.push(format!("{rel}:{line}: {lit:?}"));
            }
        }
    }
    assert!(
        count > 1000,
        "only {count} string literals read: the scanner is broken"
    );
    assert!(
        found.is_empty(),
        "library strings naming a CLI flag (say it in library terms; the CLI's hint.rs adds \
         the flag):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_scanner_sees_flags_in_every_kind_of_literal() {
    let src = concat!(
        "// \"--in-comment\"\n",
        "fn f<'a>(x: &'a str) -> char { let _ = \"use --estimator ols\"; '\"' }\n",
        "const R: &str = r#\"raw --min-speed\"#;\n",
        "const S: &str = \"esc \\\" --gains\";\n",
    );
    let lits = literals(src);
    let flagged: Vec<usize> = lits
        .iter()
        .filter(|(_, t)| names_a_flag(t))
        .map(|(l, _)| *l)
        .collect();
    assert_eq!(flagged, vec![2, 3, 4], "{lits:?}");
    assert!(!names_a_flag("a -- b, x--"));
}
