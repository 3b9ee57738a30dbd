//! Which "symmetric links" assumption could give Table 10.3's simplified figures?
//!
//! The chapter's simplified case (standard 295 / 245, base 243 / 118) assumes "symmetric links"
//! without listing which parameters vanish. This sweep zeroes, on every link, each of the 64
//! subsets of {XY, XZ, YZ, MX, MY, MZ} and generates the SR400's customized closed-chain model
//! (no friction, rotor inertias kept) with standard parameters and with the symbolic method's
//! base parameters (a grouped parameter vanishes when its grouping expression does); one more
//! row adds XX = YY (a body of revolution about z_j) to XY = XZ = YZ = MX = MY = 0. It prints
//! the operation counts, fewest base-model additions first, and marks the rows that are at or
//! below the book in both cells:
//!
//! ```text
//!  cargo run --release -p robodyn --example table_10_3_simplified
//! ```
//!
//! See docs/models/generated-code.md for what the sweep shows.

use robodyn::codegen::{generate, BaseParameters, GenOptions, GroupedParameter, ModelKind};
use robodyn::Expr;

const CANDIDATES: [&str; 6] = ["XY", "XZ", "YZ", "MX", "MY", "MZ"];
const BOOK_STANDARD: (usize, usize) = (295, 245);
const BOOK_BASE: (usize, usize) = (243, 118);

/// `XY3` -> true when its kind is in `zeros`.
fn vanishes(zeros: &[&str], name: &str) -> bool {
    let kind = name.trim_end_matches(|c: char| c.is_ascii_digit());
    kind.len() < name.len() && zeros.contains(&kind)
}

/// Standard parameters in `zeros` set to zero, on the standard or the base-parameter model;
/// with `xx_is_yy`, XX_j = YY_j as well.
fn parameters(
    desc: &robodyn::RobotDescription,
    zeros: &[&str],
    xx_is_yy: bool,
    base: bool,
) -> robodyn::Result<BaseParameters> {
    let mut p = if base {
        BaseParameters::symbolic(desc, true, false)?
    } else {
        BaseParameters::default()
    };
    let sub = |s: &str| match s.strip_prefix("XX") {
        Some(j) if xx_is_yy && j.parse::<usize>().is_ok() => Some(Expr::symbol(format!("YY{j}"))),
        _ => vanishes(zeros, s).then(Expr::zero),
    };
    if xx_is_yy && !base {
        // XX_j takes the value of the symbol YY_j
        p.grouped = (1..=desc.nl)
            .map(|j| GroupedParameter {
                replaces: format!("XX{j}"),
                name: format!("YY{j}"),
                expr: Expr::symbol(format!("YY{j}")),
            })
            .collect();
    }
    let (kept, vanished): (Vec<_>, Vec<_>) = p
        .grouped
        .into_iter()
        .map(|g| GroupedParameter {
            expr: g.expr.substitute(&sub).expand(),
            ..g
        })
        .partition(|g| !g.expr.is_zero());
    p.grouped = kept;
    p.zero.extend(vanished.into_iter().map(|g| g.replaces));
    for j in 1..=desc.nl {
        for z in zeros {
            let name = format!("{z}{j}");
            if !p.grouped.iter().any(|g| g.replaces == name) {
                p.zero.insert(name);
            }
        }
    }
    Ok(p)
}

fn main() -> robodyn::Result<()> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
    let desc = robodyn::io::load_description(std::path::Path::new(path))?;
    let mut rows = Vec::new();
    let mut cases: Vec<(Vec<&str>, bool)> = (0..64u32)
        .map(|mask| {
            let zeros = (0..6)
                .filter(|i| mask >> i & 1 == 1)
                .map(|i| CANDIDATES[i])
                .collect();
            (zeros, false)
        })
        .collect();
    cases.push((vec!["XY", "XZ", "YZ", "MX", "MY"], true));
    for (zeros, xx_is_yy) in cases {
        let count = |base: bool| -> robodyn::Result<(usize, usize)> {
            let opt = GenOptions {
                model: ModelKind::Closed,
                friction: false,
                rotor: true,
                base: Some(parameters(&desc, &zeros, xx_is_yy, base)?),
                ..Default::default()
            };
            let c = generate(&desc, &opt)?.count();
            Ok((c.mul, c.add))
        };
        let label = zeros.join(" ") + if xx_is_yy { ", XX = YY" } else { "" };
        rows.push((label, count(false)?, count(true)?));
    }
    rows.sort_by_key(|r| (r.2 .1, r.2 .0));
    println!("SR400 closed-chain model; book: standard {BOOK_STANDARD:?}, base {BOOK_BASE:?}");
    println!(
        "{:24} {:>16} {:>16}",
        "zero on every link", "standard", "base"
    );
    let within = |c: (usize, usize), b: (usize, usize)| c.0 <= b.0 && c.1 <= b.1;
    for (zeros, s, b) in rows {
        let mark = if within(s, BOOK_STANDARD) && within(b, BOOK_BASE) {
            "  <= book in both"
        } else {
            ""
        };
        let zeros = if zeros.is_empty() {
            "(none)".into()
        } else {
            zeros
        };
        println!(
            "{zeros:32} {:>7} / {:<6} {:>7} / {:<6}{mark}",
            s.0, s.1, b.0, b.1
        );
    }
    Ok(())
}
