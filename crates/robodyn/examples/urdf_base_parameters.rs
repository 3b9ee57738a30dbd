//! Base inertial parameters of a robot read from URDF (the Stäubli RX-90): the numerical method
//! (stacked regressor, rank, ordered QR; §10.2.4), the base parameter names and their values for
//! the URDF's inertias, and a check that the base model reproduces the torques.
//!
//! Run: `cargo run --release -p robodyn --example urdf_base_parameters`

use nalgebra::DVector;
use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, NumericOptions, ParameterNames, TreeSampler,
};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode};
use robodyn::{inverse_dynamics, regressor};

fn main() -> robodyn::Result<()> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    let robot = robodyn::io::load(path)?;
    // inertial parameters only (URDF damping/friction would add FV, FS)
    let selection = ParameterSelection::new(&robot, RotorMode::None, Friction::None);
    let opt = NumericOptions {
        selection,
        samples: None,
        seed: 1,
    };
    let base = numeric_base_parameters(&robot, &mut TreeSampler, &opt)?;
    let k = robot.standard_parameters();
    let values = base.base_values(&k);
    println!("{}: {} base parameters", robot.name(), base.count());
    // names as the file gives them; a base parameter that groups others gets an R (XX2R)
    let names = ParameterNames::of(robot.description());
    for (r, v) in values.iter().enumerate() {
        let i = base.base[r];
        let name = if base.is_regrouped(r) {
            names.grouped(i)
        } else {
            names.name(i)
        };
        println!("  {name:>6} = {v:.6}  = {}", base.equation(r, &names));
    }
    // Gamma = Phi_b K_b + Gamma_e at a random-looking state: the base model is exact
    let n = robot.dof();
    let (q, qd, qdd) = (vec![0.3; n], vec![-0.5; n], vec![1.0; n]);
    let phi = regressor(&robot, &q, &qd, &qdd)?;
    let gamma_b = DVector::from_iterator(
        n,
        (0..n).map(|r| {
            base.base
                .iter()
                .zip(&values)
                .map(|(&c, v)| phi[(r, c)] * v)
                .sum::<f64>()
        }),
    );
    let gamma = inverse_dynamics(&robot, &q, &qd, &qdd)?;
    println!(
        "max |Phi_b K_b - Gamma| = {:.1e} N m",
        (gamma_b - gamma).amax()
    );
    Ok(())
}
