//! Physical consistency of the inertial parameters of a description: what a real rigid body
//! can have. The loaders run it and return what it finds as warnings (a file may describe
//! parameters that are not a body's on purpose, e.g. base parameters; a command that needs a
//! body decides whether a warning is an error).
//!
//! The ten inertial parameters of a link must be those of a rigid body with a non-negative mass
//! density: its pseudo-inertia positive semi-definite, the one definition of
//! [`crate::model::inertial`] (identification's consistent fit enforces the same), reported
//! with the condition violated ("Ixx + Iyy < Izz at the centre of mass (0.1 + 0.2 < 0.5)").
//! Rotor inertia and friction coefficients must be non-negative.

use crate::error::Item;
use crate::io::Warning;
use crate::model::inertial::{body_inconsistency, Inconsistency};
use crate::model::{param, RobotDescription, STANDARD_PARAMETERS};
use crate::report::number::Sig;

/// Check every link whose inertial parameters have numeric values (links with a symbol without
/// a value are skipped). One warning per problem, naming the link.
pub fn physical_consistency(desc: &RobotDescription) -> Vec<Warning> {
    let env = |s: &str| desc.symbols.get(s).copied();
    let mut out = Vec::new();
    for (idx, l) in desc.links.iter().enumerate() {
        let j = idx + 1;
        let v: Vec<Option<f64>> = l.params.iter().map(|e| e.eval(&env).ok()).collect();
        for k in [param::M, param::IA, param::FS, param::FV] {
            if let Some(x) = v[k].filter(|x| *x < 0.0) {
                let name = STANDARD_PARAMETERS[k];
                out.push(Warning::new(
                    Item::Link(j, Some(name.into())),
                    format!("{name} = {} is negative", Sig(x, 6)),
                ));
            }
        }
        let inertial: Option<Vec<f64>> = v[..=param::M].iter().copied().collect();
        if let Some(p) = inertial {
            // a negative M is reported above
            if let Some(reason) =
                body_inconsistency(&p).filter(|r| !matches!(r, Inconsistency::NegativeMass(_)))
            {
                out.push(Warning::new(Item::Link(j, None), reason.to_string()));
            }
        }
    }
    out
}
