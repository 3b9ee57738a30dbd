//! Numerical method for the base parameters on 30- and 100-link random trees and on the SR400
//! closed chain (loop-closure sampler), and the symbolic rules.

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, symbolic_base_parameters, ClosedChainSampler, NumericOptions,
    TreeSampler,
};
use robodyn::algorithms::regressor::{
    tree_regressor, Friction, ParameterSelection, RotorMode, PARAMS_PER_LINK,
};
use robodyn::Data;
use robodyn_testing::{random_state, random_tree, rng, TreeOptions};

fn bench(c: &mut Criterion) {
    let mut r = rng(30);
    let robot = random_tree(&mut r, 30, &TreeOptions::default());
    let sel = ParameterSelection::new(&robot, RotorMode::All, Friction::Actuated);
    let opt = NumericOptions {
        selection: sel.clone(),
        samples: None,
        seed: 1,
    };
    let mut g = c.benchmark_group("base_parameters");
    g.sample_size(10);
    g.bench_function("numeric_30_joint_tree", |b| {
        b.iter(|| numeric_base_parameters(&robot, &mut TreeSampler, &opt).unwrap())
    });
    // growth: a 100-link tree (the example base_parameters_scale goes to 500 links)
    let big = random_tree(&mut rng(100), 100, &TreeOptions::default());
    let big_opt = NumericOptions {
        selection: ParameterSelection::new(&big, RotorMode::Actuated, Friction::Actuated),
        samples: None,
        seed: 1,
    };
    g.bench_function("numeric_100_link_tree", |b| {
        b.iter(|| numeric_base_parameters(&big, &mut TreeSampler, &big_opt).unwrap())
    });
    g.bench_function("symbolic_30_joint_tree", |b| {
        b.iter(|| symbolic_base_parameters(robot.description(), &sel).unwrap())
    });
    // SR400 closed chain (Table 10.2 selection): loop-closure sampler built once per run, as the
    // CLI does
    let sr400 = robodyn::io::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/sr400.toml"
    )))
    .unwrap();
    let sr_opt = NumericOptions {
        selection: ParameterSelection::new(&sr400, RotorMode::Actuated, Friction::None),
        samples: None,
        seed: 1,
    };
    g.bench_function("numeric_sr400_closed_chain", |b| {
        b.iter(|| {
            let mut s = ClosedChainSampler::new(&sr400).unwrap();
            numeric_base_parameters(&sr400, &mut s, &sr_opt).unwrap()
        })
    });
    g.finish();
    let [q, qd, qdd] = random_state(&mut r, 30);
    let mut ws = Data::new(&robot);
    let mut phi = nalgebra::DMatrix::zeros(30, PARAMS_PER_LINK * 30);
    c.bench_function("regressor_30_joint_tree", |b| {
        b.iter(|| {
            tree_regressor(
                robot.numeric(),
                &mut ws,
                &robot.numeric().env,
                &q,
                &qd,
                &qdd,
                &mut phi,
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
