//! One module per subcommand.

pub mod base_params;
pub mod closure;
pub mod convert;
pub mod ddm;
pub mod excite;
pub mod generate;
pub mod identify;
pub mod idm;
pub mod inertia;
pub mod info;
pub mod regressor;
pub mod simulate;
pub mod view;
