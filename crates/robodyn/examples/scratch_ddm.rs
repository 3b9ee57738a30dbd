// scratch (not committed): profile direct_dynamics_derivatives_into
use robodyn::algorithms::derivatives::{
    direct_dynamics_derivatives_into, inverse_dynamics_derivatives_into, DdmDerivatives,
    DerivativesData, IdmDerivatives,
};
use robodyn::model::param;
use std::hint::black_box;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let robot = robodyn::io::load(&a[1]).unwrap();
    let mut k = robot.standard_parameters();
    for link in k.chunks_mut(13) {
        link[param::IA] = 0.0;
        link[param::FS] = 0.0;
        link[param::FV] = 0.0;
    }
    let robot = robot.with_standard_parameters(&k).unwrap();
    let n = robot.dof();
    let which = a[2].as_str();
    let reps: usize = a[3].parse().unwrap();
    let mut dd = DerivativesData::new(&robot);
    let mut da = DdmDerivatives::new(&robot);
    let mut di = IdmDerivatives::new(&robot);
    let env = robot.environment().clone();
    let states: Vec<Vec<f64>> = (0..16)
        .map(|s| {
            (0..n)
                .map(|i| ((i * 7 + s * 13) % 11) as f64 * 0.1 - 0.5)
                .collect()
        })
        .collect();
    let t = std::time::Instant::now();
    for r in 0..reps {
        let q = black_box(&states[r % 16]);
        if which == "aba" {
            direct_dynamics_derivatives_into(&robot, &mut dd, &env, q, q, q, &mut da).unwrap();
        } else {
            inverse_dynamics_derivatives_into(&robot, &mut dd, &env, q, q, q, &mut di).unwrap();
        }
    }
    println!(
        "n {n} {which} {:.2} us",
        t.elapsed().as_secs_f64() * 1e6 / reps as f64
    );
}
