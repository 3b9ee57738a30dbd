//! One module per subcommand.

pub mod ddm;
pub mod idm;
pub mod inertia;
pub mod info;
pub mod simulate;
