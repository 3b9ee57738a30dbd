//! One module per subcommand.

pub mod convert;
pub mod idm;
pub mod info;
