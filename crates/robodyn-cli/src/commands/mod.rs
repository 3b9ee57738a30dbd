//! One module per subcommand.

pub mod base_params;
pub mod closure;
pub mod com;
pub mod convert;
pub mod ddm;
pub mod excite;
pub mod fk;
pub mod generate;
pub mod identify;
pub mod idm;
pub mod ik;
pub mod inertia;
pub mod info;
pub mod jacobian;
pub mod regressor;
pub mod simulate;
pub mod view;
