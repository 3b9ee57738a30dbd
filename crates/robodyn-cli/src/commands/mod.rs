//! One module per subcommand.

pub mod base_params;
pub mod closure;
pub mod convert;
pub mod idm;
pub mod info;
pub mod regressor;
