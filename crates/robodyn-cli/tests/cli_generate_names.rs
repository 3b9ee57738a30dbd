//! `generate --name` (issue 24 item 15): a name that is not an identifier of the target language,
//! one of its reserved words, or a name the generated code uses itself is refused with the rule
//! it breaks, before anything is written (it wrote code that did not compile, or injected C).

mod common;

use common::process::robodyn_within;
use common::robot;

const LANGS: [&str; 7] = ["text", "latex", "rust", "c", "python", "julia", "matlab"];

#[test]
fn bad_function_names_are_refused_per_language() {
    let rx90 = robot("rx90.toml");
    let d = std::env::temp_dir().join(format!("robodyn_names_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let file = d.join("model.out");
    // refused in every language: not identifiers
    let everywhere = [
        "my func",
        "1abc",
        "f(void){}int x",
        "",
        "a-b",
        "é",
        "x\ny",
        "_",
    ];
    // reserved in some languages only
    let some = [
        ("lambda", "python"),
        ("def", "python"),
        ("fn", "rust"),
        ("self", "rust"),
        ("void", "c"),
        ("exp", "c"),
        ("__init", "c"),
        ("end", "julia"),
        ("function", "matlab"),
        ("_private", "matlab"),
        ("q", "c"),
        ("out", "python"),
        ("np", "python"),
        ("sin", "julia"),
    ];
    let cases: Vec<(&str, &str)> = everywhere
        .iter()
        .flat_map(|n| LANGS.iter().map(move |l| (*n, *l)))
        .chain(some)
        .collect();
    for (name, lang) in cases {
        let r = robodyn_within(
            &[
                "generate",
                &rx90,
                "--lang",
                lang,
                "--name",
                name,
                "--output",
                file.to_str().unwrap(),
            ],
            60.0,
        );
        r.assert_no_crash("generate");
        assert_eq!(r.code, Some(1), "--name {name:?} --lang {lang}: accepted");
        assert!(r.stderr.contains("--name"), "{}", r.stderr);
        assert!(
            !file.exists(),
            "--name {name:?} --lang {lang}: a file was written"
        );
    }
    // a reserved word of one language is a fine name in another
    for (name, lang) in [
        ("lambda", "c"),
        ("end", "python"),
        ("fn", "julia"),
        ("exp", "rust"),
    ] {
        let r = robodyn_within(&["generate", &rx90, "--lang", lang, "--name", name], 60.0);
        assert_eq!(r.code, Some(0), "--name {name} --lang {lang}: {}", r.stderr);
        assert!(r.stdout.contains(name), "{lang}");
    }
    // a name that is fine everywhere
    for lang in LANGS {
        let r = robodyn_within(
            &["generate", &rx90, "--lang", lang, "--name", "rx90_tau"],
            60.0,
        );
        assert_eq!(r.code, Some(0), "{lang}: {}", r.stderr);
        // text and LaTeX name the function on standard error only (the operation counts)
        assert!(
            r.stdout.contains("rx90_tau") || r.stderr.contains("rx90_tau"),
            "{lang}"
        );
    }
}
