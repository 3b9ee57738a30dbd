//! Writers of the results for people and other programs (text, LaTeX, JSON), apart from the
//! algorithms that compute them.

pub mod base_parameters;
#[cfg(feature = "plot")]
pub mod figure;
pub mod number;

pub use number::{format_number, significant, Number, Sig};
