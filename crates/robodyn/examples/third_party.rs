//! A program as a user of the crate writes it, against the public API only: robots from files
//! (the bundled TOML and URDF), inverse dynamics, the inertia matrix in place, direct dynamics,
//! base parameters and a closed chain, each result checked by another route.
//!
//! `cargo run --release --example third_party` (run by `cargo test` too: its test calls `main`).

use robodyn::algorithms::base_parameters::ParameterNames;
use robodyn::algorithms::base_parameters::{numeric_base_parameters_auto, NumericOptions};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode};
use robodyn::nalgebra::{DMatrix, DVector}; // robodyn's own nalgebra, re-exported
use robodyn::State;
use robodyn::{closed_inverse_dynamics, direct_dynamics_state_into, inertia_matrix_into};
use robodyn::{inverse_dynamics, regressor_state_into, ClosedChain, Data, DirectState, Method};
use std::path::Path;

/// Largest absolute difference of two vectors.
fn gap(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let robots = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    // 1. robots from files: the Stäubli RX-90 as robodyn TOML and as URDF
    let rx90 = robodyn::io::load(robots.join("rx90.toml"))?;
    let urdf = robodyn::io::load(robots.join("rx90.urdf"))?;
    let n = rx90.dof();
    println!("{}: {n} joints, {} from URDF", rx90.name(), urdf.dof());

    // 2. inverse dynamics (allocating form, the file's gravity)
    let (q, qd, qdd) = ([0.1, -0.4, 0.7, 0.2, -0.3, 0.5], [0.3; 6], [-0.2; 6]);
    let tau = inverse_dynamics(&rx90, &q, &qd, &qdd)?;
    println!("tau = {:.4?}", tau.as_slice());

    // 3. the inertia matrix in place, column k checked against Newton-Euler:
    //    A e_k = idm(q, 0, e_k) - idm(q, 0, 0)
    let mut data = Data::new(&rx90);
    let mut a = DMatrix::zeros(n, n);
    inertia_matrix_into(&rx90, &mut data, &q, &mut a)?;
    let rest = inverse_dynamics(&rx90, &q, &[0.0; 6], &[0.0; 6])?;
    for k in 0..n {
        let mut e = [0.0; 6];
        e[k] = 1.0;
        let column = inverse_dynamics(&rx90, &q, &[0.0; 6], &e)? - &rest;
        assert!(gap(column.as_slice(), a.column(k).as_slice()) < 1e-10);
    }
    println!("A(q) diagonal = {:.4?}", a.diagonal().as_slice());

    // 4. direct dynamics, both methods, back to qdd from the torques of step 2
    let env = rx90.environment();
    let mut back = [0.0; 6];
    let inputs = DirectState {
        q: &q,
        qd: &qd,
        tau: tau.as_slice(),
    };
    for method in [Method::Composite, Method::ArticulatedBody] {
        direct_dynamics_state_into(&rx90, &mut data, env, inputs, method, &mut back)?;
        assert!(gap(&back, &qdd) < 1e-9, "{method:?}");
    }

    // 5. base parameters of the URDF robot (numerical method), checked on one state:
    //    Phi_base K_base = Phi K
    let selection = ParameterSelection::new(&urdf, RotorMode::None, Friction::Actuated);
    let options = NumericOptions::new(selection);
    let (base, _closed_start) = numeric_base_parameters_auto(&urdf, &options)?;
    let names = ParameterNames::of(urdf.description());
    println!("{} base parameters of {}:", base.count(), urdf.name());
    for r in 0..base.count().min(4) {
        println!("  {}", base.equation(r, &names));
    }
    let k = urdf.standard_parameters();
    let mut phi = DMatrix::zeros(urdf.dof(), 13 * urdf.nl());
    let state = State {
        q: &q,
        qd: &qd,
        qdd: &qdd,
    };
    regressor_state_into(
        &urdf,
        &mut Data::new(&urdf),
        urdf.environment(),
        state,
        &mut phi,
    )?;
    let k_base = base.base_values(&k);
    let phi_base = phi.select_columns(&base.base);
    let by_base = &phi_base * DVector::from_vec(k_base);
    let by_standard = &phi * DVector::from_vec(k);
    assert!(gap(by_base.as_slice(), by_standard.as_slice()) < 1e-9);

    // 6. a closed chain: the Acma SR400 (parallelogram loop), torques of the actuated joints on
    //    the file's assembly branch, (10.40) checked against the multiplier form (10.36)
    let sr400 = robodyn::io::load(robots.join("sr400.toml"))?;
    let chain = ClosedChain::new(&sr400)?;
    let mut branch = chain.assembly_branch()?;
    let q_a = [0.1, 0.2, 0.3, 0.4, 0.5, 1.6];
    let idm = closed_inverse_dynamics(&chain, &mut branch, &q_a, &[0.1; 6], &[0.2; 6])?;
    let lagrange = idm.gamma_cl_lagrange.as_slice();
    assert!(gap(idm.gamma_cl.as_slice(), lagrange) < 1e-8);
    assert!(!idm.state.conditioning.warning);
    println!("SR400 Gamma_cl = {:.4?}", idm.gamma_cl.as_slice());
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
