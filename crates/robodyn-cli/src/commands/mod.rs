//! One module per subcommand.

pub mod generate;
pub mod idm;
pub mod info;
