//! The command line's hints: the library's errors and warnings say what is wrong in library
//! terms (an options field, a method); here each is translated into the flag to change.
//!
//! Matched on structured data ([`robodyn::Error::Setting`]'s options field, an identification
//! warning's kind), never on the wording of a message.

use robodyn::identification::{Warning, WarningKind};
use robodyn::Error;

/// The flag hint for a library error (None when the error needs none).
pub fn hint(e: &Error) -> Option<String> {
    let Error::Setting { option, .. } = e.innermost() else {
        return None;
    };
    let text = match *option {
        "identification::Options::estimator" => "noise-free data: --estimator ols",
        "identification::Options::validation" => {
            "give a validation segment, e.g. --validation 0.8:1, with --plot"
        }
        "base_parameters::NumericOptions::selection" => {
            "--method symbolic, or fewer drive parameters: --rotor none, --no-friction"
        }
        "codegen::GenOptions::base" => {
            "compute the base parameters with `robodyn base-params --method numeric` and pass \
             them with --base-file"
        }
        "codegen::Frames::frame" => "choose frame j with --frame J (1..NL)",
        "codegen::Frames::reference" => "choose frame i with --reference I (0: the base) or local",
        _ => return None,
    };
    Some(text.to_string())
}

/// The flag hint for a warning of `robodyn identify` (None when it needs none).
pub fn warning_hint(w: &Warning) -> Option<&'static str> {
    match w.kind {
        WarningKind::IvNotConverged => {
            Some("more iterations: --iv-iterations; a slower tracking loop: --iv-bandwidth")
        }
        WarningKind::PoorlyIdentified => Some("--essential drops them"),
        _ => None,
    }
}

/// The robodyn error in a command's error chain, if any.
pub fn library_error<'a>(e: &'a (dyn std::error::Error + 'static)) -> Option<&'a Error> {
    let mut cur = Some(e);
    while let Some(e) = cur {
        if let Some(r) = e.downcast_ref::<Error>() {
            return Some(r);
        }
        cur = e.source();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_map_to_flags() {
        let e = Error::Setting {
            option: "identification::Options::estimator",
            reason: "sigma = 0".into(),
        };
        assert_eq!(
            hint(&e).as_deref(),
            Some("noise-free data: --estimator ols")
        );
        // inside a row of a table too
        assert!(hint(&e.clone().in_row(3)).is_some());
        assert_eq!(hint(&Error::Input("x".into())), None);
    }
}
