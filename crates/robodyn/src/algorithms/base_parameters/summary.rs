//! The base parameters of a robot by one method as a structured result (what the CLI prints and
//! a Python binding returns): a per-link table like Table 10.2 (R suffix for grouped
//! parameters, 0 for eliminated ones, `-` for parameters that are not in the model), the lists
//! of parameters with no effect and of grouped ones, the grouping equations in the robot's own
//! names, the values, and the comparison of the two methods. The writers (text, LaTeX, JSON)
//! are in [`crate::report::base_parameters`]. Also: the base robot (`--write-robot`).

use super::names::ParameterNames;
use super::numeric::NumericBase;
use super::symbolic::{collect_by_coefficient, SymbolicBase};
use crate::error::{Error, Item, Result};
use crate::model::PARAMS_PER_LINK;
use crate::model::{param, RobotDescription, STANDARD_PARAMETERS};
use crate::report::number::{format_number, significant};
use robodyn_symbolic::Expr;

/// One base parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseEntry {
    /// Index in K (13 per link).
    pub index: usize,
    /// Display name in the robot's names: `XXR2` when grouped, `XY2` when alone.
    pub name: String,
    /// Whether it is a combination of parameters (the `R` name).
    pub regrouped: bool,
    /// Grouping equation (right-hand side) as text, in the robot's names.
    pub equation: String,
    /// Numeric value for the robot's values, when every parameter involved has one.
    pub value: Option<f64>,
}

/// Base parameters of a robot by one method.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Robot name.
    pub robot: String,
    /// `symbolic` or `numeric`.
    pub method: &'static str,
    /// NL, the number of links.
    pub nl: usize,
    /// Standard parameters of the model (selected and existing), K indices.
    pub columns: Vec<usize>,
    /// The robot's names of the standard parameters.
    pub names: ParameterNames,
    /// The base parameters, in K order of the parameter each one is kept as.
    pub base: Vec<BaseEntry>,
    /// Names of the parameters with no effect.
    pub no_effect: Vec<String>,
    /// Names of the parameters grouped into base parameters.
    pub grouped: Vec<String>,
    /// What the user must know about the result (start of a closed chain, generic values).
    pub notes: Vec<String>,
    /// Comparison with the other method (`--method both`).
    pub comparison: Option<MethodComparison>,
}

/// Numeric standard parameters of a description, K order (None where a symbol has no value);
/// a floating base's link 0 after the links (K indices 13 NL..).
pub fn standard_values(desc: &RobotDescription) -> Vec<Option<f64>> {
    let env = |s: &str| desc.symbols.get(s).copied();
    desc.links
        .iter()
        .chain(&desc.floating_base)
        .flat_map(|l| {
            l.params
                .iter()
                .map(|e| e.eval(&env).ok())
                .collect::<Vec<_>>()
        })
        .collect()
}

impl Summary {
    /// From the symbolic method.
    pub fn from_symbolic(
        desc: &RobotDescription,
        sb: &SymbolicBase,
        names: &ParameterNames,
    ) -> Summary {
        let values = sb.values(desc, &standard_values(desc));
        let base = sb
            .base
            .iter()
            .enumerate()
            .map(|(r, &i)| {
                let regrouped = sb.is_regrouped(r);
                BaseEntry {
                    index: i,
                    name: entry_name(names, i, regrouped),
                    regrouped,
                    equation: collect_by_coefficient(&sb.equations[r], names),
                    value: values[r],
                }
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
                "loop cut at joint {l}: not a parallelogram; of its cut-joint relations (10.51) \
                 the rules use none, so the symbolic set may be larger than the minimal one (the \
                 numerical method is the arbiter)"
            ));
        }
        if sb.dropped_float_terms > 0 {
            notes.push(format!(
                "{} grouping term(s) with a float coefficient below the tolerance {} L^k were \
                 taken as 0 (rounding noise of the file's floats; L = {} m the robot's largest \
                 length, k the length power the coefficient's unit has; exact coefficients are \
                 never dropped)",
                sb.dropped_float_terms,
                significant(super::symbolic::FLOAT_TERM_TOLERANCE, 3),
                significant(sb.length_scale, 6)
            ));
        }
        Summary {
            robot: desc.name.clone(),
            method: "symbolic",
            nl: desc.nl,
            columns: sb.columns.clone(),
            names: names.clone(),
            base,
            no_effect: sb.no_effect.iter().map(|&i| names.name(i).into()).collect(),
            grouped: sb.grouped.iter().map(|&i| names.name(i).into()).collect(),
            notes,
            comparison: None,
        }
    }

    /// From the numerical method; `k`: the robot's standard parameters (K order, None where
    /// a symbol has no value: the values of the base parameters involving it are left out).
    pub fn from_numeric(
        desc: &RobotDescription,
        nb: &NumericBase,
        names: &ParameterNames,
        k: &[Option<f64>],
    ) -> Summary {
        let known: Vec<f64> = k.iter().map(|v| v.unwrap_or(0.0)).collect();
        let values = nb.base_values(&known);
        let base = nb
            .base
            .iter()
            .enumerate()
            .map(|(r, &i)| {
                let regrouped = nb.is_regrouped(r);
                let involved = std::iter::once(i).chain(
                    nb.grouped
                        .iter()
                        .enumerate()
                        .filter(|&(c, _)| nb.beta[(r, c)].abs() > 1e-9)
                        .map(|(_, &g)| g),
                );
                let complete = involved
                    .filter(|x| !nb.absent.contains(x))
                    .all(|x| k.get(x).copied().flatten().is_some());
                BaseEntry {
                    index: i,
                    name: entry_name(names, i, regrouped),
                    regrouped,
                    equation: nb.equation(r, names),
                    value: complete.then_some(values[r]),
                }
            })
            .collect();
        let mut note = format!(
            "{} sample rows, rank tolerance {} on unit columns (kept columns: smallest singular \
             value {}; grouped columns: residual {}); coefficients are numbers for the robot's \
             geometry (rounded for display only)",
            nb.rows,
            significant(nb.tolerance, 3),
            significant(nb.sigma_min_kept, 3),
            significant(nb.residual_grouped, 3)
        );
        if !nb.absent.is_empty() {
            note.push_str(&format!(
                "; {} parameter(s) written as a literal 0 are not parameters",
                nb.absent.len()
            ));
        }
        Summary {
            robot: desc.name.clone(),
            method: "numeric",
            nl: desc.nl,
            columns: nb.columns.clone(),
            names: names.clone(),
            base,
            no_effect: nb.no_effect.iter().map(|&i| names.name(i).into()).collect(),
            grouped: nb.grouped.iter().map(|&i| names.name(i).into()).collect(),
            notes: vec![note],
            comparison: None,
        }
    }

    /// Number of base parameters.
    pub fn count(&self) -> usize {
        self.base.len()
    }

    /// Whether every base parameter has a value.
    pub fn has_values(&self) -> bool {
        self.base.iter().all(|b| b.value.is_some())
    }

    /// Which of the 13 per-link parameters appear in the table (those selected for some link).
    fn table_columns(&self) -> Vec<usize> {
        (0..PARAMS_PER_LINK)
            .filter(|p| self.columns.iter().any(|c| c % PARAMS_PER_LINK == *p))
            .collect()
    }

    /// Per-link table like Table 10.2 (first row: headers `j`, `XXj`, ...): the base
    /// parameter's name (R suffix when it is a combination), `0` when the parameter is grouped
    /// into another or has no effect, `-` when it is not a parameter of the model (drive
    /// parameter not selected, or written as a literal 0 in a SYMORO file).
    pub fn table(&self) -> Vec<Vec<String>> {
        let cols = self.table_columns();
        let mut rows = vec![std::iter::once("j".to_string())
            .chain(cols.iter().map(|&p| format!("{}j", STANDARD_PARAMETERS[p])))
            .collect()];
        // a floating base's link 0 (K indices 13 NL..) first
        let floating = self
            .columns
            .last()
            .is_some_and(|&c| c >= PARAMS_PER_LINK * self.nl);
        let links = (!floating as usize)..=self.nl;
        for j in links {
            let mut row = vec![j.to_string()];
            for &p in &cols {
                let first = if j == 0 { self.nl } else { j - 1 };
                let idx = PARAMS_PER_LINK * first + p;
                row.push(match self.base.iter().find(|b| b.index == idx) {
                    Some(b) => b.name.clone(),
                    None if self.columns.binary_search(&idx).is_ok() => "0".into(),
                    None => "-".into(),
                });
            }
            rows.push(row);
        }
        rows
    }

    /// Record the comparison with the other method (a note first; the writers print a block
    /// under the title when the sets differ).
    pub fn add_comparison(&mut self, c: &MethodComparison) {
        self.notes.insert(0, c.note());
        self.comparison = Some(c.clone());
    }
}

/// The legend of the table (Table 10.2's conventions).
pub const LEGEND: &str = "XXR2: base parameter that groups other parameters (R before the \
    link number; the equation below gives it); XY2: base parameter alone; 0: parameter grouped \
    into a base parameter or without effect; -: not a parameter of the model (drive parameter \
    not selected, or written as a literal 0 in a SYMORO file)";

fn entry_name(names: &ParameterNames, i: usize, regrouped: bool) -> String {
    if regrouped {
        names.grouped(i).into()
    } else {
        names.name(i).into()
    }
}

/// Shortest round-trip text of a float (the data form of [`crate::report::number`]).
pub fn short(x: f64) -> String {
    format_number(x)
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
    for l in d.links.iter_mut().chain(d.floating_base.as_mut()) {
        for e in l.params.iter_mut() {
            *e = Expr::zero();
        }
    }
    let names = if desc.floating_base.is_some() {
        ParameterNames::of(desc)
    } else {
        ParameterNames::standard(desc.nl)
    };
    for (&i, &v) in base.iter().zip(values) {
        // a floating base's link 0 after the links (K indices 13 NL..)
        let (j, p) = (
            (i / PARAMS_PER_LINK + 1) % (desc.nl + 1),
            i % PARAMS_PER_LINK,
        );
        if matches!(p, param::M | param::IA | param::FS | param::FV) && v < 0.0 {
            return Err(Error::invalid(
                Item::Link(j, Some(STANDARD_PARAMETERS[p].into())),
                format!(
                    "the grouped value {} = {v} is negative: it is a combination of parameters, \
                     not a physical {}, and cannot be written as one in a robot file",
                    names.grouped(i),
                    STANDARD_PARAMETERS[p]
                ),
            ));
        }
        match (j, d.floating_base.as_mut()) {
            (0, Some(l)) => l.params[p] = Expr::num(v),
            _ => d.links[j - 1].params[p] = Expr::num(v),
        }
    }
    d.name = format!("{} (base parameters)", desc.name);
    d.notes.push(
        "Base robot: every standard parameter is zero except the base parameters, which hold \
         their grouped values."
            .into(),
    );
    Ok(d)
}

/// How the symbolic rules and the numerical method compare on one robot (§10.3.4: for loops
/// that are not parallelograms the rules do not use the cut-joint relations (10.51), so their
/// set can be larger; the numerical method is then the arbiter).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MethodComparison {
    /// Number of base parameters by the symbolic rules.
    pub symbolic_count: usize,
    /// Number of base parameters by the numerical method.
    pub numeric_count: usize,
    /// Base by the symbolic rules but grouped or without effect numerically.
    pub symbolic_only: Vec<String>,
    /// Base numerically but grouped or without effect by the symbolic rules.
    pub numeric_only: Vec<String>,
    /// Cut joints of the loops the symbolic rules did not fully handle.
    pub unhandled_loops: Vec<usize>,
    /// Cut joints of the parallelogram loops (handled by 10.51c, 10.55, 10.56).
    pub parallelograms: Vec<usize>,
}

/// Compare the base sets of the two methods (names from `names`).
pub fn compare_methods(
    sb: &SymbolicBase,
    nb: &NumericBase,
    names: &ParameterNames,
) -> MethodComparison {
    let only = |a: &[usize], b: &[usize]| -> Vec<String> {
        a.iter()
            .filter(|i| !b.contains(i))
            .map(|&i| names.name(i).to_string())
            .collect()
    };
    MethodComparison {
        symbolic_count: sb.count(),
        numeric_count: nb.count(),
        symbolic_only: only(&sb.base, &nb.base),
        numeric_only: only(&nb.base, &sb.base),
        unhandled_loops: sb.unhandled_loops.clone(),
        parallelograms: sb.parallelograms.clone(),
    }
}

impl MethodComparison {
    /// Why the rules may give more parameters than the numerical method on this robot.
    pub fn reason(&self) -> String {
        let mut why = Vec::new();
        if !self.unhandled_loops.is_empty() {
            why.push(format!(
                "the loop(s) cut at joint(s) {:?} are not parallelograms: the rules do not use \
                 their cut-joint relations (10.51; \"no general systematic choice\", §10.3.4)",
                self.unhandled_loops
            ));
        }
        if !self.parallelograms.is_empty() {
            why.push(format!(
                "through the parallelogram(s) cut at joint(s) {:?} some links keep the \
                 orientation of a lower link (10.54), so a link can turn about an axis fixed \
                 to a lower link or move in a plane normal to gravity although its tree path \
                 says otherwise: rules 5–7 are stated on the tree's branches (r1, r2) and do \
                 not see these eliminations",
                self.parallelograms
            ));
        }
        if why.is_empty() {
            "a relation the rules do not express".into()
        } else {
            why.join("; ")
        }
    }

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
        let why = format!(" ({})", self.reason());
        format!(
            "METHODS DIFFER: the symbolic rules give {} base parameters, the numerical method {}. \
             The NUMERICAL method is the arbiter (its set is minimal){why}. Base by the rules \
             only (grouped or without effect numerically): {}. Base numerically only: {}. The \
             symbolic equations above remain valid groupings but are not minimal; the numerical \
             method gives the minimal set.",
            self.symbolic_count,
            self.numeric_count,
            list(&self.symbolic_only),
            list(&self.numeric_only)
        )
    }

    /// The block printed under the title when the methods differ (None when they agree).
    pub fn block(&self) -> Option<String> {
        if self.same() {
            return None;
        }
        Some(format!(
            "THE METHODS DIFFER; THE NUMERICAL METHOD IS THE ARBITER: it finds {} base parameters, \
             the symbolic rules {} ({}).\n  base by the rules only: {}\n  base numerically only: {}\n\
             The table and equations below are the symbolic ones (valid, not minimal); \
             the numerical method gives the minimal set.\n\n",
            self.numeric_count,
            self.symbolic_count,
            self.reason(),
            list(&self.symbolic_only),
            list(&self.numeric_only)
        ))
    }
}

fn list(v: &[String]) -> String {
    if v.is_empty() {
        "none".to_string()
    } else {
        v.join(", ")
    }
}
