//! One module per subcommand.

pub mod idm;
pub mod info;
