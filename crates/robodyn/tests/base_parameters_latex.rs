//! `base-params --format latex` typesets: the base-parameter reports (table with math cells,
//! legend, grouping equations broken between terms, values) of the SR400 (Table 10.2, with the
//! comparison comment), the RX-90 and the Orthoglide (its own names: `MR11` is link 1's)
//! go through pdflatex in a minimal document (amsmath) with no error and no overfull line.
//! `.ci/run` installs pdflatex and sets ROBODYN_REQUIRE=all (a missing install fails there).

mod common;

use robodyn::algorithms::base_parameters::{
    compare_methods, geometry_robot, numeric_base_parameters_auto, standard_values,
    symbolic_base_parameters, NumericOptions, ParameterNames, Summary,
};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode, ZeroParameters};
use std::path::Path;
use std::process::{Command, Stdio};

fn report(path: &Path, friction: Friction, both: bool) -> Summary {
    let desc = robodyn::io::load_description(path).unwrap();
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, friction)
        .with_zero_parameters(&desc, ZeroParameters::for_path(path));
    let names = ParameterNames::of(&desc);
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    let mut r = Summary::from_symbolic(&desc, &sb, &names);
    if both {
        let (robot, _) = geometry_robot(&desc).unwrap();
        let opt = NumericOptions {
            selection: sel,
            samples: None,
            seed: 1,
        };
        let (nb, _) = numeric_base_parameters_auto(&robot, &opt).unwrap();
        r.add_comparison(&compare_methods(&sb, &nb, &names));
        // the numeric report of the same robot typesets too (rational coefficients)
        let rn = Summary::from_numeric(&desc, &nb, &names, &standard_values(&desc));
        assert_eq!(rn.count(), r.count());
    }
    r
}

#[test]
fn base_parameter_latex_typesets() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sr400 = report(&root.join("robots/sr400.toml"), Friction::None, true);
    let latex = robodyn::report::base_parameters::latex(&sr400);
    // checks that need no pdflatex: math cells, values, legend
    assert!(latex.contains("$ZZR_{1}$ & 0"), "{latex}");
    assert!(latex.contains("Legend"), "{latex}");
    assert!(latex.contains("Values:"), "{latex}");
    assert!(latex.contains("ZZR_{1} &= "), "{latex}");
    assert!(
        latex.contains("&\\quad "),
        "ZZR1 is broken over lines: {latex}"
    );
    if !common::tool_available(
        "pdflatex",
        &["--version"],
        "latex",
        "base-parameter LaTeX (Debian package texlive-latex-base)",
    ) {
        return;
    }
    let mut docs = vec![("sr400", latex)];
    let rx90 = report(&root.join("robots/rx90.toml"), Friction::Actuated, false);
    docs.push(("rx90", robodyn::report::base_parameters::latex(&rx90)));
    // the Orthoglide (SYMORO+ file, own names) when shared/ is there
    let mut dir = Some(Path::new(env!("CARGO_MANIFEST_DIR")));
    while let Some(d) = dir {
        let f = d.join("shared/cases/external/freecad-symoro/orthoglide.par");
        if f.exists() {
            let r = report(&f, Friction::Actuated, false);
            let tex = robodyn::report::base_parameters::latex(&r);
            // link 1's mass is the file's M11: grouped, MR11 (no robodyn name for link 11)
            assert!(tex.contains("$MR_{11}$"), "{tex}");
            docs.push(("orthoglide", tex));
            break;
        }
        dir = d.parent();
    }
    let tmp = std::env::temp_dir().join(format!("robodyn-bp-latex-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    for (stem, tex) in docs {
        let doc = format!(
            "\\documentclass{{article}}\n\\usepackage{{amsmath}}\n\\allowdisplaybreaks\n\
             \\begin{{document}}\n{tex}\\end{{document}}\n"
        );
        std::fs::write(tmp.join(format!("{stem}.tex")), doc).unwrap();
        let out = Command::new("pdflatex")
            .args(["-interaction=nonstopmode", "-halt-on-error"])
            .arg(format!("{stem}.tex"))
            .current_dir(&tmp)
            .stdin(Stdio::null())
            .output()
            .unwrap();
        let log = std::fs::read_to_string(tmp.join(format!("{stem}.log"))).unwrap();
        let errors: Vec<&str> = log.lines().filter(|l| l.starts_with('!')).collect();
        assert!(
            out.status.success(),
            "{stem}: pdflatex failed:\n{}",
            errors.join("\n")
        );
        assert!(
            !log.contains("Overfull \\hbox"),
            "{stem}: a line is wider than the text:\n{}",
            log.lines()
                .filter(|l| l.starts_with("Overfull"))
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
    std::fs::remove_dir_all(&tmp).ok();
}
