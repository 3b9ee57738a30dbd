//! One module per subcommand.

pub mod closure;
pub mod idm;
pub mod info;
