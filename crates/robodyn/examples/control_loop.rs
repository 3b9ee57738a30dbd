//! A control loop at 1 kHz: computed-torque feed-forward of the Stäubli RX-90 (URDF) along a
//! trajectory, with a contact force on the last link that changes at every tick. After the
//! `Data` is built nothing is allocated: the model is shared, the buffers reused, the contact
//! force is a field of the per-call `Environment`, not a new robot.
//!
//! Run: `cargo run --release -p robodyn --example control_loop`

use robodyn::{inverse_dynamics_into, Data};

fn main() -> robodyn::Result<()> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    let robot = robodyn::io::load(path)?;
    let n = robot.dof(); // the movable joints, in frame order
    let mut data = Data::new(&robot); // one per thread
    let mut env = robot.environment().clone(); // gravity, base motion, wrenches of the file
    let last = robot.nl(); // the link the contact force acts on
    let (mut q, mut qd, mut qdd, mut tau) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut peak = vec![0.0f64; n];
    for tick in 0..2000 {
        let t = tick as f64 * 1e-3;
        for k in 0..n {
            let w = 1.0 + 0.2 * k as f64;
            q[k] = 0.5 * (w * t).sin();
            qd[k] = 0.5 * w * (w * t).cos();
            qdd[k] = -0.5 * w * w * (w * t).sin();
        }
        // a contact force pushing ON the last link (Pinocchio's fext convention), in its frame
        let push = 20.0 * (10.0 * t).sin().max(0.0);
        env.set_wrench_on_link(last, [0.0, 0.0, push].into(), [0.0; 3].into())?;
        inverse_dynamics_into(&robot, &mut data, &env, &q, &qd, &qdd, &mut tau)?;
        for (p, t) in peak.iter_mut().zip(&tau) {
            *p = p.max(t.abs());
        }
    }
    let names = robot.coordinates().names();
    for (name, p) in names.iter().zip(&peak) {
        println!("{name:>12}: peak torque {p:8.2} N m");
    }
    Ok(())
}
