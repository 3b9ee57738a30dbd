//! A closed-chain trajectory: the Acma SR400 (parallelogram loop) along a smooth path of its
//! actuated joints, torques by Γ_cl = G^T Γ_tr (10.40) on one branch tracker. Each evaluation
//! continues the tracker from the previous point, so every row is on the assembly branch of the
//! file (the parallelogram, not its crossed form), and each result comes with the conditioning
//! of Wp. Prints CSV: t, q_a, Γ_cl, rcond(Wp).
//!
//! Run: `cargo run --release -p robodyn --example closed_chain_trajectory`

use robodyn::{closed_inverse_dynamics_into, ClosedChain, ClosedData};

fn main() -> robodyn::Result<()> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
    let robot = robodyn::io::load(path)?;
    let chain = ClosedChain::new(&robot)?;
    let mut branch = chain.assembly_branch()?; // explicit branch state, owned here
    let mut data = ClosedData::new(&chain);
    let coords = chain.coordinates(); // actuated joints 1, 2, 4, 5, 6, 7
    let n = coords.len();
    let q0 = branch.q_a().to_vec();
    let header: Vec<String> = ["t".to_string()]
        .into_iter()
        .chain((0..n).map(|k| format!("q{}", coords.frame(k))))
        .chain((0..n).map(|k| format!("tau{}", coords.frame(k))))
        .chain(["rcond_wp".to_string()])
        .collect();
    println!("{}", header.join(","));
    let (mut q, mut qd, mut qdd, mut tau) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for row in 0..=20 {
        let t = row as f64 * 0.1;
        for k in 0..n {
            q[k] = q0[k] + 0.4 * (t + k as f64).sin() - 0.4 * (k as f64).sin();
            qd[k] = 0.4 * (t + k as f64).cos();
            qdd[k] = -0.4 * (t + k as f64).sin();
        }
        let c = closed_inverse_dynamics_into(
            &chain,
            &mut data,
            &mut branch,
            robot.environment(),
            &q,
            &qd,
            &qdd,
            &mut tau,
        )
        .map_err(|e| e.in_row(row + 1))?;
        let cells: Vec<String> = [t]
            .iter()
            .chain(&q)
            .chain(&tau)
            .chain([c.wp].iter())
            .map(|x| format!("{x:.6}"))
            .collect();
        println!("{}", cells.join(","));
        if c.warning {
            eprintln!("row {}: near a singular configuration", row + 1);
        }
    }
    Ok(())
}
