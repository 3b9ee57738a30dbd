//! Presentation of the base parameters: a per-link table like Table 10.2 (R suffix for grouped
//! parameters, 0 for eliminated ones), the lists of parameters with no effect and of grouped
//! ones, the grouping equations as text, LaTeX or JSON, and the base robot.

use super::numeric::NumericBase;
use super::symbolic::{collect_by_coefficient, SymbolicBase};
use crate::algorithms::regressor::{parameter_name, PARAMS_PER_LINK};
use crate::error::{Error, Item, Result};
use crate::model::{param, RobotDescription, STANDARD_PARAMETERS};
use robodyn_symbolic::Expr;
use serde_json::json;

/// One base parameter.
#[derive(Clone, Debug)]
pub struct BaseEntry {
    /// Index in K (13 per link).
    pub index: usize,
    /// Display name: `XXR2` when grouped, `XY2` when alone.
    pub name: String,
    /// Grouping equation (right-hand side) as text.
    pub equation: String,
    /// Numeric value for the robot's values, when every symbol has one.
    pub value: Option<f64>,
}

/// Base parameters of a robot by one method, ready to print.
#[derive(Clone, Debug)]
pub struct Report {
    pub robot: String,
    pub method: &'static str,
    pub nl: usize,
    /// Selected standard parameters (K indices).
    pub columns: Vec<usize>,
    pub base: Vec<BaseEntry>,
    pub no_effect: Vec<String>,
    pub grouped: Vec<String>,
    pub notes: Vec<String>,
    /// Comparison with the other method (`--method both`).
    pub comparison: Option<MethodComparison>,
}

/// Name with the R suffix of grouped parameters: `XXR2`.
pub fn grouped_name(index: usize) -> String {
    format!(
        "{}R{}",
        STANDARD_PARAMETERS[index % PARAMS_PER_LINK],
        index / PARAMS_PER_LINK + 1
    )
}

/// Numeric standard parameters of a description (None where a symbol has no value).
pub fn standard_values(desc: &RobotDescription) -> Vec<Option<f64>> {
    let env = |s: &str| desc.symbols.get(s).copied();
    desc.links
        .iter()
        .flat_map(|l| {
            l.params
                .iter()
                .map(|e| e.eval(&env).ok())
                .collect::<Vec<_>>()
        })
        .collect()
}

impl Report {
    /// From the symbolic method.
    pub fn from_symbolic(desc: &RobotDescription, sb: &SymbolicBase) -> Report {
        let values = sb.values(desc, &standard_values(desc));
        let base = sb
            .base
            .iter()
            .enumerate()
            .map(|(r, &i)| BaseEntry {
                index: i,
                name: if sb.is_regrouped(r) {
                    grouped_name(i)
                } else {
                    parameter_name(i)
                },
                equation: collect_by_coefficient(&sb.equations[r], desc.nl),
                value: values[r],
            })
            .collect();
        let mut notes = Vec::new();
        for p in &sb.parallelograms {
            notes.push(format!(
                "loop cut at joint {p}: parallelogram (eqs 10.51c, 10.55, 10.56)"
            ));
        }
        for l in &sb.unhandled_loops {
            notes.push(format!(
                "loop cut at joint {l}: not a parallelogram; its cut-joint relations (10.51) are \
                 not used, so the symbolic set may be larger than the minimal one (the numerical \
                 method is the arbiter)"
            ));
        }
        Report {
            robot: desc.name.clone(),
            method: "symbolic",
            nl: desc.nl,
            columns: sb.columns.clone(),
            base,
            no_effect: sb.no_effect.iter().map(|&i| parameter_name(i)).collect(),
            grouped: sb.grouped.iter().map(|&i| parameter_name(i)).collect(),
            notes,
            comparison: None,
        }
    }

    /// From the numerical method (`k`: the robot's standard parameters, 13 per link).
    pub fn from_numeric(desc: &RobotDescription, nb: &NumericBase, k: &[f64]) -> Report {
        let values = nb.base_values(k);
        let base = nb
            .base
            .iter()
            .enumerate()
            .map(|(r, &i)| {
                let regrouped = (0..nb.grouped.len()).any(|c| nb.beta[(r, c)].abs() > 1e-9);
                BaseEntry {
                    index: i,
                    name: if regrouped {
                        grouped_name(i)
                    } else {
                        parameter_name(i)
                    },
                    equation: nb.equation(r),
                    value: Some(values[r]),
                }
            })
            .collect();
        Report {
            robot: desc.name.clone(),
            method: "numeric",
            nl: desc.nl,
            columns: nb.columns.clone(),
            base,
            no_effect: nb.no_effect.iter().map(|&i| parameter_name(i)).collect(),
            grouped: nb.grouped.iter().map(|&i| parameter_name(i)).collect(),
            notes: vec![format!(
                "{} sample rows, rank tolerance {:.3e} on unit columns; coefficients are \
                 numbers for the robot's geometry (rounded for display only)",
                nb.rows, nb.tolerance
            )],
            comparison: None,
        }
    }

    pub fn count(&self) -> usize {
        self.base.len()
    }

    /// Which of the 13 per-link parameters appear in the table (those selected for some link).
    fn table_columns(&self) -> Vec<usize> {
        (0..PARAMS_PER_LINK)
            .filter(|p| self.columns.iter().any(|c| c % PARAMS_PER_LINK == *p))
            .collect()
    }

    /// Per-link table like Table 10.2: name (R suffix when grouped), 0 when eliminated or
    /// grouped, `-` when not a parameter of the model.
    pub fn table(&self) -> Vec<Vec<String>> {
        let cols = self.table_columns();
        let mut rows = vec![std::iter::once("j".to_string())
            .chain(cols.iter().map(|&p| format!("{}j", STANDARD_PARAMETERS[p])))
            .collect()];
        for j in 1..=self.nl {
            let mut row = vec![j.to_string()];
            for &p in &cols {
                let idx = PARAMS_PER_LINK * (j - 1) + p;
                row.push(match self.base.iter().find(|b| b.index == idx) {
                    Some(b) => b.name.clone(),
                    None if self.columns.contains(&idx) => "0".into(),
                    None => "-".into(),
                });
            }
            rows.push(row);
        }
        rows
    }

    /// Plain-text report.
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "{}: {} base parameters ({} method)\n\n",
            self.robot,
            self.count(),
            self.method
        );
        if let Some(b) = self.comparison_block() {
            s.push_str(&b);
        }
        let t = self.table();
        let w: Vec<usize> = (0..t[0].len())
            .map(|c| t.iter().map(|r| r[c].len()).max().unwrap_or(1))
            .collect();
        for r in &t {
            let line: Vec<String> = r.iter().zip(&w).map(|(x, &n)| format!("{x:<n$}")).collect();
            s.push_str(line.join("  ").trim_end());
            s.push('\n');
        }
        s.push_str(&format!(
            "\nNo effect ({}): {}\n",
            self.no_effect.len(),
            self.no_effect.join(", ")
        ));
        s.push_str(&format!(
            "Grouped ({}): {}\n\nGrouping equations:\n",
            self.grouped.len(),
            self.grouped.join(", ")
        ));
        for b in &self.base {
            if b.name != parameter_name(b.index) {
                s.push_str(&format!("  {} = {}\n", b.name, b.equation));
            }
        }
        s.push_str("\nValues:\n");
        for b in &self.base {
            match b.value {
                Some(v) => {
                    let v = if format!("{v:.9}") == "-0.000000000" {
                        0.0
                    } else {
                        v
                    };
                    s.push_str(&format!("  {:<6} = {v:.9}\n", b.name))
                }
                None => s.push_str(&format!("  {:<6} = (symbols without value)\n", b.name)),
            }
        }
        for n in &self.notes {
            s.push_str(&format!("\nNote: {n}"));
        }
        if !self.notes.is_empty() {
            s.push('\n');
        }
        s
    }

    /// LaTeX: the table (tabular) and the grouping equations (align*).
    pub fn to_latex(&self) -> String {
        let t = self.table();
        let mut s = format!(
            "% {}: {} base parameters ({} method)\n\\begin{{tabular}}{{{}}}\n",
            self.robot,
            self.count(),
            self.method,
            "c".repeat(t[0].len())
        );
        if let Some(b) = self.comparison_block() {
            let lines: Vec<String> = b.lines().map(|l| format!("% {l}")).collect();
            s.insert_str(
                s.find('\n').map_or(0, |i| i + 1),
                &format!("{}\n", lines.join("\n")),
            );
        }
        for (k, r) in t.iter().enumerate() {
            let cells: Vec<String> = r.iter().map(|x| latex_name(x)).collect();
            s.push_str(&format!("{} \\\\\n", cells.join(" & ")));
            if k == 0 {
                s.push_str("\\hline\n");
            }
        }
        s.push_str("\\end{tabular}\n\n\\begin{align*}\n");
        for b in &self.base {
            if b.name != parameter_name(b.index) {
                s.push_str(&format!(
                    "{} &= {} \\\\\n",
                    latex_name(&b.name),
                    latex_equation(&b.equation)
                ));
            }
        }
        s.push_str("\\end{align*}\n");
        s
    }

    /// JSON: `count`, `base` [{name, equation, value}], `no_effect`, `grouped`, and with both
    /// methods `comparison` {arbiter, same, symbolic_count, numeric_count, symbolic_only,
    /// numeric_only}.
    pub fn to_json(&self) -> serde_json::Value {
        let mut o = json!({
            "robot": self.robot,
            "method": self.method,
            "count": self.count(),
            "base": self.base.iter().map(|b| json!({
                "name": b.name,
                "equation": b.equation,
                "value": b.value,
            })).collect::<Vec<_>>(),
            "no_effect": self.no_effect,
            "grouped": self.grouped,
            "notes": self.notes,
        });
        if let Some(c) = &self.comparison {
            o["comparison"] = json!({
                "arbiter": "numeric",
                "same": c.same(),
                "symbolic_count": c.symbolic_count,
                "numeric_count": c.numeric_count,
                "symbolic_only": c.symbolic_only,
                "numeric_only": c.numeric_only,
            });
        }
        o
    }
}

/// `XXR2` -> `XXR_{2}`, `IA4` -> `I_{a4}`, `d3` -> `d_{3}`, `RL4` -> `RL_{4}`.
fn latex_name(n: &str) -> String {
    match n.find(|c: char| c.is_ascii_digit()) {
        Some(k) if k > 0 && n[k..].chars().all(|c| c.is_ascii_digit()) => {
            let (a, d) = n.split_at(k);
            if a == "IA" {
                format!("I_{{a{d}}}")
            } else {
                format!("{a}_{{{d}}}")
            }
        }
        _ => n.to_string(),
    }
}

/// Text equation to LaTeX: names subscripted, `*` dropped, `^k` braced, `/` as a fraction
/// of the adjacent factors.
fn latex_equation(e: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    let flush = |w: &mut String, out: &mut String| {
        if !w.is_empty() {
            out.push_str(&latex_name(w));
            w.clear();
        }
    };
    for c in e.chars() {
        if c.is_ascii_alphanumeric() || c == '_' || c == '.' {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            match c {
                '*' => out.push(' '),
                '/' => out.push_str(" / "),
                _ => out.push(c),
            }
        }
    }
    flush(&mut word, &mut out);
    out.replace("^2", "^{2}").replace("pi", "\\pi")
}

/// The base robot: same geometry, every standard parameter zero except the base parameters,
/// which hold their grouped values (`values` in the order of `base`). Parameters outside the
/// selection are zero too, so the base robot reproduces the torques of the selected model.
///
/// A grouped mass (MR_j) or rotor inertia can be negative (e.g. a rotor grouped into a mass,
/// MR_j = M_j + IA_j with -IA_j moved to a(j)); such a value is not a physical mass and the
/// robot loader rejects it, so it is reported as an error naming the parameter.
pub fn base_robot(
    desc: &RobotDescription,
    base: &[usize],
    values: &[f64],
) -> Result<RobotDescription> {
    let mut d = desc.clone();
    for l in d.links.iter_mut() {
        for e in l.params.iter_mut() {
            *e = Expr::zero();
        }
    }
    for (&i, &v) in base.iter().zip(values) {
        let (j, p) = (i / PARAMS_PER_LINK + 1, i % PARAMS_PER_LINK);
        if matches!(p, param::M | param::IA | param::FS | param::FV) && v < 0.0 {
            return Err(Error::invalid(
                Item::Link(j, Some(STANDARD_PARAMETERS[p].into())),
                format!(
                    "the grouped value {} = {v} is negative: it is a combination of parameters, \
                     not a physical {}, and cannot be written as one in a robot file",
                    grouped_name(i),
                    STANDARD_PARAMETERS[p]
                ),
            ));
        }
        d.links[j - 1].params[p] = Expr::num(v);
    }
    d.name = format!("{} (base parameters)", desc.name);
    d.notes.push(
        "Base robot: every standard parameter is zero except the base parameters, which hold \
         their grouped values (robodyn base-params --write-robot)."
            .into(),
    );
    Ok(d)
}

/// How the symbolic rules and the numerical method compare on one robot (§10.3.4: for loops
/// that are not parallelograms the rules do not use the cut-joint relations (10.51), so their
/// set can be larger; the numerical method is then the arbiter).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MethodComparison {
    pub symbolic_count: usize,
    pub numeric_count: usize,
    /// Base by the symbolic rules but grouped or without effect numerically.
    pub symbolic_only: Vec<String>,
    /// Base numerically but grouped or without effect by the symbolic rules.
    pub numeric_only: Vec<String>,
    /// Cut joints of the loops the symbolic rules did not fully handle.
    pub unhandled_loops: Vec<usize>,
}

/// Compare the base sets of the two methods.
pub fn compare_methods(sb: &SymbolicBase, nb: &NumericBase) -> MethodComparison {
    let only = |a: &[usize], b: &[usize]| -> Vec<String> {
        a.iter()
            .filter(|i| !b.contains(i))
            .map(|&i| parameter_name(i))
            .collect()
    };
    MethodComparison {
        symbolic_count: sb.count(),
        numeric_count: nb.count(),
        symbolic_only: only(&sb.base, &nb.base),
        numeric_only: only(&nb.base, &sb.base),
        unhandled_loops: sb.unhandled_loops.clone(),
    }
}

impl MethodComparison {
    /// Same base set.
    pub fn same(&self) -> bool {
        self.symbolic_only.is_empty() && self.numeric_only.is_empty()
    }

    /// One note for the report: agreement, or which method is the arbiter and which
    /// parameters differ.
    pub fn note(&self) -> String {
        if self.same() {
            return format!(
                "numerical method: {} base parameters, the same set as the symbolic rules",
                self.numeric_count
            );
        }
        let list = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(", ")
            }
        };
        let why = if self.unhandled_loops.is_empty() {
            String::new()
        } else {
            format!(
                " (the rules do not use the cut-joint relations (10.51) of the loop(s) cut at \
                 joint(s) {:?})",
                self.unhandled_loops
            )
        };
        format!(
            "METHODS DIFFER: the symbolic rules give {} base parameters, the numerical method {}. \
             The NUMERICAL method is the arbiter (its set is minimal){why}. Base by the rules \
             only (grouped or without effect numerically): {}. Base numerically only: {}. The \
             symbolic equations above remain valid groupings but are not minimal; use \
             `--method numeric` for the minimal set.",
            self.symbolic_count,
            self.numeric_count,
            list(&self.symbolic_only),
            list(&self.numeric_only)
        )
    }
}

impl Report {
    /// Record the comparison with the other method: a note, and when the sets differ a block
    /// right under the title of the text report (and `comparison` in JSON).
    pub fn add_comparison(&mut self, c: &MethodComparison) {
        self.notes.insert(0, c.note());
        self.comparison = Some(c.clone());
    }

    /// The block printed under the title when the methods differ.
    fn comparison_block(&self) -> Option<String> {
        let c = self.comparison.as_ref().filter(|c| !c.same())?;
        let list = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(", ")
            }
        };
        Some(format!(
            "THE METHODS DIFFER; THE NUMERICAL METHOD IS THE ARBITER: it finds {} base parameters, \
             the symbolic rules {}{}.\n  base by the rules only: {}\n  base numerically only: {}\n\
             The table and equations below are the symbolic ones (valid, not minimal); \
             `--method numeric` gives the minimal set.\n\n",
            c.numeric_count,
            c.symbolic_count,
            if c.unhandled_loops.is_empty() {
                String::new()
            } else {
                format!(
                    " (the loop(s) cut at joint(s) {:?} are not parallelograms: their cut-joint \
                     relations 10.51 are not used by the rules)",
                    c.unhandled_loops
                )
            },
            list(&c.symbolic_only),
            list(&c.numeric_only)
        ))
    }
}
