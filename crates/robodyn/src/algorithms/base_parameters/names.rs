//! Names of the standard parameters in a robot's own words.
//!
//! The methods compute with the canonical symbols `XX2`, `M3` (parameter and link number, 13
//! per link in K). A file may name its parameters its own way (SYMORO+'s Orthoglide writes
//! `XX21` for link 4's XX and `M11` for link 1's mass): reports use the file's names, and the
//! names robodyn makes up (for a parameter the file gives as a number or a literal 0, and the
//! grouped `R` names) never clash with a symbol of the file (a clash gets `_` appended).

use crate::model::PARAMS_PER_LINK;
use crate::model::{RobotDescription, STANDARD_PARAMETERS};
use robodyn_symbolic::Expr;
use std::collections::{BTreeSet, HashMap};

/// Display names of the standard parameters (K order) and of their grouped (`R`) versions.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterNames {
    names: Vec<String>,
    grouped: Vec<String>,
    /// NL (a floating base's link 0 comes after the links in K: indices 13 NL..).
    nl: usize,
}

/// Canonical name of standard parameter `k` (K index) of a robot with `nl` links: `XX1`, ...,
/// `FV<NL>`, then a floating base's `XX0` ... `M0`.
fn canonical(k: usize, nl: usize) -> String {
    let link = k / PARAMS_PER_LINK;
    format!(
        "{}{}",
        STANDARD_PARAMETERS[k % PARAMS_PER_LINK],
        if link == nl { 0 } else { link + 1 }
    )
}

/// `XX21` -> `XXR21` (the parameter's prefix then R), otherwise the name then R.
fn grouped_of(prefix: &str, name: &str) -> String {
    match name.strip_prefix(prefix) {
        Some(rest) if rest.starts_with(|c: char| c.is_ascii_digit()) => {
            format!("{prefix}R{rest}")
        }
        _ => format!("{name}R"),
    }
}

fn unique(mut name: String, used: &BTreeSet<String>, taken: &BTreeSet<String>) -> String {
    while used.contains(&name) || taken.contains(&name) {
        name.push('_');
    }
    name
}

impl ParameterNames {
    /// The canonical names `XX1`...`FV<nl>` and `XXR1`...`FVR<nl>`.
    pub fn standard(nl: usize) -> ParameterNames {
        let names: Vec<String> = (0..PARAMS_PER_LINK * nl)
            .map(|k| canonical(k, nl))
            .collect();
        let grouped = names
            .iter()
            .enumerate()
            .map(|(k, n)| grouped_of(STANDARD_PARAMETERS[k % PARAMS_PER_LINK], n))
            .collect();
        ParameterNames { names, grouped, nl }
    }

    /// The names `desc` gives its parameters: a parameter written as a single symbol keeps that
    /// symbol (the first one only, if a symbol names two parameters); any other (a number, a
    /// literal 0, an expression) takes its canonical name unless the file uses that name for
    /// something else. A floating base's link 0 follows the links (K indices 13 NL..).
    pub fn of(desc: &RobotDescription) -> ParameterNames {
        let mut used: BTreeSet<String> = desc.symbols.keys().cloned().collect();
        used.extend(desc.used_symbols());
        let nl = desc.nl;
        let links: Vec<_> = desc.links.iter().chain(&desc.floating_base).collect();
        let n = PARAMS_PER_LINK * links.len();
        let own: Vec<Option<String>> = (0..n)
            .map(|k| {
                links[k / PARAMS_PER_LINK].params[k % PARAMS_PER_LINK]
                    .as_symbol()
                    .map(str::to_string)
            })
            .collect();
        let mut taken: BTreeSet<String> = BTreeSet::new();
        let mut names = vec![String::new(); n];
        // the file's own names first, so that a made-up name never takes one of them
        for k in 0..n {
            if let Some(s) = &own[k] {
                if taken.insert(s.clone()) {
                    names[k] = s.clone();
                }
            }
        }
        for k in 0..n {
            if names[k].is_empty() {
                names[k] = unique(canonical(k, nl), &used, &taken);
                taken.insert(names[k].clone());
            }
        }
        let mut grouped = Vec::with_capacity(n);
        for (k, name) in names.iter().enumerate() {
            let g = unique(
                grouped_of(STANDARD_PARAMETERS[k % PARAMS_PER_LINK], name),
                &used,
                &taken,
            );
            taken.insert(g.clone());
            grouped.push(g);
        }
        ParameterNames { names, grouped, nl }
    }

    /// Number of links (NL, without a floating base's link 0).
    pub fn nl(&self) -> usize {
        self.nl
    }

    /// Name of standard parameter `k` (K index).
    pub fn name(&self, k: usize) -> &str {
        &self.names[k]
    }

    /// Name of the grouped parameter that takes the place of `k` (`XXR2`).
    pub fn grouped(&self, k: usize) -> &str {
        &self.grouped[k]
    }

    /// Whether the names differ from the canonical `XX1`... (the file has its own).
    pub fn is_canonical(&self) -> bool {
        let s = ParameterNames::standard(self.nl);
        self.names
            .iter()
            .enumerate()
            .all(|(k, n)| *n == canonical(k, self.nl))
            && self.grouped[..s.grouped.len()] == s.grouped[..]
    }

    /// `e` (over the canonical symbols) with the canonical symbols replaced by these names.
    pub fn rename(&self, e: &Expr) -> Expr {
        let map: HashMap<String, usize> = (0..self.names.len())
            .map(|k| (canonical(k, self.nl), k))
            .collect();
        e.substitute(&|s: &str| map.get(s).map(|&k| Expr::symbol(self.names[k].clone())))
    }
}
