//! Base parameters of closed chains through the general loop-closure sampler, and of every
//! bundled robot. Cross-checks: the base model (regressor G^T Phi_b times grouped values) against
//! the closed-chain inverse dynamic model Gamma_cl of `ClosedChain` (Newton–Euler on the
//! equivalent tree projected by G, an independent route); the two methods against each other;
//! counts against the bounds 10.24 / 10.57.
#[path = "common/frames.rs"]
mod frames;

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use robodyn::algorithms::base_parameters::inertial_bound;
use robodyn::algorithms::base_parameters::{
    compare_methods, numeric_base_parameters, symbolic_base_parameters, ClosedChainSampler,
    NumericBase, NumericOptions, ParameterNames, Sampler, Summary, SymbolicBase, TreeSampler,
};
use robodyn::algorithms::regressor::{
    parameter_name, tree_regressor, tree_wrench_torques, Friction, ParameterSelection, RotorMode,
    PARAMS_PER_LINK,
};
use robodyn::{closed_inverse_dynamics, inverse_dynamics, ClosedChain};
use robodyn::{Data, Robot};
use robodyn_testing::{random_inertial, rng};

fn load(file: &str) -> Robot {
    let path = format!("{}/../../robots/{file}", env!("CARGO_MANIFEST_DIR"));
    robodyn::io::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

const TREES: [&str; 5] = [
    "rx90.toml",
    "rx90.par",
    "rx90.urdf",
    "torso2arms.toml",
    "scara.toml",
];
const CLOSED: [&str; 6] = [
    "sr400.toml",
    "sr400.par",
    "fourbar.toml",
    "fivebar.toml",
    "spatial_loop.toml",
    "twoloops.toml",
];

fn names(v: &[usize]) -> Vec<String> {
    v.iter().map(|&i| parameter_name(i)).collect()
}

fn expected(list: &str) -> Vec<String> {
    list.split_whitespace().map(String::from).collect()
}

/// A grouping as a linear map: base value r = sum_c coef[(r, c)] K[columns[c]].
struct Grouping {
    base: Vec<usize>,
    columns: Vec<usize>,
    coef: DMatrix<f64>,
}

impl Grouping {
    fn numeric(nb: &NumericBase) -> Grouping {
        let mut coef = DMatrix::zeros(nb.base.len(), nb.columns.len());
        for (c, &col) in nb.columns.iter().enumerate() {
            if let Some(r) = nb.base.iter().position(|&b| b == col) {
                coef[(r, c)] = 1.0;
            } else if let Some(g) = nb.grouped.iter().position(|&b| b == col) {
                coef.set_column(c, &nb.beta.column(g));
            }
        }
        Grouping {
            base: nb.base.clone(),
            columns: nb.columns.clone(),
            coef,
        }
    }

    /// The symbolic equations are linear in K: their coefficients are their values at K = e_c.
    fn symbolic(sb: &SymbolicBase, robot: &Robot) -> Grouping {
        let nk = PARAMS_PER_LINK * robot.nl();
        let mut coef = DMatrix::zeros(sb.base.len(), sb.columns.len());
        for (c, &col) in sb.columns.iter().enumerate() {
            let mut k = vec![Some(0.0); nk];
            k[col] = Some(1.0);
            for (r, v) in sb.values(robot.description(), &k).into_iter().enumerate() {
                coef[(r, c)] = v.expect("every symbol has a value");
            }
        }
        Grouping {
            base: sb.base.clone(),
            columns: sb.columns.clone(),
            coef,
        }
    }

    /// The standard parameter whose column the base model reproduces worst on the regressor
    /// y (rows x 13 NL): y_c against sum_r y_{base r} coef[(r, c)].
    fn worst_parameter(&self, y: &DMatrix<f64>) -> (String, f64) {
        let mut worst = (String::new(), -1.0);
        for (c, &col) in self.columns.iter().enumerate() {
            let mut d = y.column(col).into_owned();
            for (r, &b) in self.base.iter().enumerate() {
                d -= y.column(b) * self.coef[(r, c)];
            }
            let e = d.amax() / y.column(col).amax().max(1e-300);
            if e > worst.1 {
                worst = (parameter_name(col), e);
            }
        }
        worst
    }
}

/// Random numeric standard parameters: physically consistent inertial parameters for every link,
/// IA, FS, FV in [0.1, 1] where selected, 0 elsewhere.
fn random_parameters(robot: &Robot, sel: &ParameterSelection, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    let mut k = Vec::new();
    for j in 0..robot.nl() {
        k.extend(random_inertial(&mut r));
        let ia: f64 = r.random_range(0.1..1.0);
        let fs: f64 = r.random_range(0.1..1.0);
        let fv: f64 = r.random_range(0.1..1.0);
        k.push(if sel.rotor[j] { ia } else { 0.0 });
        k.push(if sel.friction[j] { fs } else { 0.0 });
        k.push(if sel.friction[j] { fv } else { 0.0 });
    }
    k
}

/// Base model (regressor columns of `base` times `values`, plus the wrench torques) against the
/// full model computed by Newton–Euler: Gamma_cl of `ClosedChain::inverse_dynamics` for a closed
/// chain, `inverse_dynamics` for a tree. Robot with the random parameters `k`, 10 states from a
/// fresh sampler. Returns the worst error relative to max |Gamma|; a mismatch panics naming the
/// standard parameter the grouping gets wrong.
fn check_against_idm(
    label: &str,
    robot: &Robot,
    k: &[f64],
    grouping: &Grouping,
    values: &[f64],
    seed: u64,
) -> f64 {
    let full = robot.with_standard_parameters(k).unwrap();
    let nl = robot.nl();
    let model = full.numeric();
    let mut ws = Data::from_model(model);
    let mut phi = DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    let mut tau_e = vec![0.0; nl];
    let mut r = rng(seed);
    let mut worst: f64 = 0.0;
    let (mut closed, mut sampler) = (None, None);
    if !robot.is_tree() {
        closed = Some(ClosedChain::new(&full).unwrap());
        sampler = Some(ClosedChainSampler::new(&full).unwrap());
    }
    for _ in 0..10 {
        let (q, qd, qdd, g, gamma) = match (&mut closed, &mut sampler) {
            (Some(cc), Some(sm)) => {
                let st = sm.next_state(&mut r).unwrap();
                let pick = |v: &DVector<f64>| -> Vec<f64> {
                    cc.coordinates()
                        .frames()
                        .iter()
                        .map(|&j| v[j - 1])
                        .collect()
                };
                let mut b = cc
                    .branch_from(st.q_a.as_slice(), st.q_p.as_slice())
                    .unwrap();
                let idm = closed_inverse_dynamics(
                    cc,
                    &mut b,
                    &pick(&st.q),
                    &pick(&st.qd),
                    &pick(&st.qdd),
                )
                .unwrap();
                let s = idm.state;
                let v = |x: DVector<f64>| -> Vec<f64> { x.iter().copied().collect() };
                (v(s.q), v(s.qd), v(s.qdd), s.g, idm.gamma_cl)
            }
            _ => {
                let s = TreeSampler.sample(&full, &mut r).unwrap();
                // the bundled trees have no fixed frame: tree arrays are the joint vectors
                assert_eq!(full.dof(), nl);
                let t = inverse_dynamics(&full, &s.q, &s.qd, &s.qdd).unwrap();
                let g = DMatrix::identity(nl, nl);
                (s.q, s.qd, s.qdd, g, t)
            }
        };
        tree_regressor(model, &mut ws, &model.env, &q, &qd, &qdd, &mut phi);
        tree_wrench_torques(model, &mut ws, &model.env, &q, &mut tau_e);
        let y = g.transpose() * &phi;
        let te = g.transpose() * DVector::from_column_slice(&tau_e);
        let scale = gamma.amax().max(1e-12);
        for row in 0..y.nrows() {
            let b: f64 = grouping
                .base
                .iter()
                .zip(values)
                .map(|(&c, v)| y[(row, c)] * v)
                .sum::<f64>()
                + te[row];
            let err = (b - gamma[row]).abs() / scale;
            if err > 1e-9 {
                let (name, e) = grouping.worst_parameter(&y);
                panic!(
                    "{label}: base model {b} vs Gamma_cl {} (row {row}, relative error {err:e}); \
                     worst grouped parameter {name} (column error {e:e})",
                    gamma[row]
                );
            }
            worst = worst.max(err);
        }
    }
    worst
}

fn numeric(robot: &Robot, sel: &ParameterSelection, seed: u64) -> NumericBase {
    let opt = NumericOptions {
        selection: sel.clone(),
        samples: None,
        seed,
    };
    if robot.is_tree() {
        numeric_base_parameters(robot, &mut TreeSampler, &opt).unwrap()
    } else {
        let mut s = ClosedChainSampler::new(robot).unwrap();
        numeric_base_parameters(robot, &mut s, &opt)
            .unwrap_or_else(|e| panic!("{}: {e}", robot.name()))
    }
}

#[test]
fn sampler_states_close_the_loops_and_satisfy_the_velocity_constraints() {
    // Independent check: the cut-joint frame and its twin coincide in position with parallel z
    // axes (geometry.rs, not the closure solver), and qd_tr = G qd_a satisfies Wa qd_a + Wp qd_p
    // = 0, checked by a central finite difference of the twin/cut placement along qd_tr.
    for file in CLOSED {
        let robot = load(file);
        let mut s = ClosedChainSampler::new(&robot).unwrap();
        let mut r = rng(17);
        let cuts: Vec<(usize, usize)> = robot
            .structure()
            .loops
            .iter()
            .map(|l| (l.cut, l.twin))
            .collect();
        for _ in 0..15 {
            let st = s.sample(&robot, &mut r).unwrap();
            let gap = |q: &[f64]| -> Vec<f64> {
                let t = frames::per_frame(&robot, q);
                cuts.iter()
                    .flat_map(|&(c, w)| {
                        let d = t[c - 1].pos - t[w - 1].pos;
                        [d.x, d.y, d.z]
                    })
                    .collect()
            };
            for (l, &(c, w)) in cuts.iter().enumerate() {
                let t = frames::per_frame(&robot, &st.q);
                let dp = (t[c - 1].pos - t[w - 1].pos).norm();
                let dz = t[c - 1].rot.column(2).cross(&t[w - 1].rot.column(2)).norm();
                assert!(
                    dp < 1e-9 && dz < 1e-9,
                    "{file}: loop {l}: gap {dp:e}, {dz:e}"
                );
            }
            let h = 1e-6;
            let plus: Vec<f64> = st.q.iter().zip(&st.qd).map(|(a, b)| a + h * b).collect();
            let minus: Vec<f64> = st.q.iter().zip(&st.qd).map(|(a, b)| a - h * b).collect();
            let (gp, gm) = (gap(&plus), gap(&minus));
            let rate = gp
                .iter()
                .zip(&gm)
                .fold(0.0f64, |a, (x, y)| a.max(((x - y) / (2.0 * h)).abs()));
            assert!(rate < 1e-6, "{file}: the loop opens at rate {rate:e}");
        }
    }
}

#[test]
fn sr400_general_sampler_gives_table_10_2() {
    for file in ["sr400.toml", "sr400.par"] {
        let robot = load(file);
        let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
        let nb = numeric(&robot, &sel, 1);
        let table = expected(
            "ZZ1 XX2 XY2 XZ2 YZ2 ZZ2 MX2 MY2 XX3 XY3 XZ3 YZ3 ZZ3 MX3 MY3 \
             XX4 XY4 XZ4 YZ4 ZZ4 MX4 MY4 IA4 XX5 XY5 XZ5 YZ5 ZZ5 MX5 MY5 IA5 \
             XX6 XY6 XZ6 YZ6 ZZ6 MX6 MY6 IA6 MX7 MY7 MY8",
        );
        assert_eq!(nb.count(), 42, "{file}");
        assert_eq!(names(&nb.base), table, "{file}");
        assert_eq!(
            names(&nb.no_effect),
            expected("XX1 XY1 XZ1 YY1 YZ1 MX1 MY1 MZ1 M1 MZ2 MZ7"),
            "{file}"
        );
        let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
        assert_eq!(names(&sb.base), names(&nb.base), "{file}");
        assert!(compare_methods(&sb, &nb, &ParameterNames::standard(robot.nl())).same());
        // values parameter by parameter: symbolic equations vs K1 + beta K2
        let k = random_parameters(&robot, &sel, 3);
        let kopt: Vec<Option<f64>> = k.iter().map(|&v| Some(v)).collect();
        let vs = sb.values(robot.description(), &kopt);
        for (r, (a, b)) in vs.iter().zip(nb.base_values(&k)).enumerate() {
            let a = a.unwrap();
            assert!(
                (a - b).abs() <= 1e-8 * (1.0 + b.abs()),
                "{file}: {}: symbolic {a} vs numeric {b}",
                parameter_name(sb.base[r])
            );
        }
        let err = check_against_idm(
            file,
            &robot,
            &k,
            &Grouping::numeric(&nb),
            &nb.base_values(&k),
            8,
        );
        eprintln!("{file}: 42 base parameters by the general sampler, Gamma_cl error {err:e}");
    }
}

#[test]
fn every_bundled_robot_counts_bounds_and_reproduces_the_full_model() {
    for (n, file) in TREES.iter().chain(CLOSED.iter()).enumerate() {
        let robot = load(file);
        for (m, (rotor, friction)) in [
            (RotorMode::Actuated, Friction::Actuated),
            (RotorMode::All, Friction::None),
        ]
        .into_iter()
        .enumerate()
        {
            let label = format!("{file} ({rotor:?} rotors, friction {friction:?})");
            let sel = ParameterSelection::new(&robot, rotor, friction);
            let seed = (10 * n + m) as u64;
            let nb = numeric(&robot, &sel, seed);
            let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
            // bound: inertial parameters <= b_m; drive parameters <= those selected
            let inertial = |b: &[usize]| b.iter().filter(|&&c| c % PARAMS_PER_LINK < 10).count();
            let bm = inertial_bound(&robot, sb.parallelograms.len());
            assert!(
                inertial(&nb.base) <= bm,
                "{label}: numeric {} > b_m {bm}",
                inertial(&nb.base)
            );
            let drive = sel.columns().len() - 10 * robot.nl();
            assert!(nb.count() <= bm + drive, "{label}");
            let cmp = compare_methods(&sb, &nb, &ParameterNames::standard(robot.nl()));
            if robot.is_tree() || sb.unhandled_loops.is_empty() {
                assert!(cmp.same(), "{label}: {}", cmp.note());
            } else {
                assert!(sb.count() >= nb.count(), "{label}: {}", cmp.note());
                if !cmp.same() {
                    let mut rep = Summary::from_symbolic(
                        robot.description(),
                        &sb,
                        &ParameterNames::of(robot.description()),
                    );
                    rep.add_comparison(&cmp);
                    let text = robodyn::report::base_parameters::text(&rep);
                    // the block under the title names the arbiter and the differing parameters
                    let head: String = text.lines().take(4).collect::<Vec<_>>().join("\n");
                    assert!(
                        head.contains("THE NUMERICAL METHOD IS THE ARBITER"),
                        "{label}: {head}"
                    );
                    assert!(!cmp.symbolic_only.is_empty() || !cmp.numeric_only.is_empty());
                    for p in cmp.symbolic_only.iter().chain(&cmp.numeric_only) {
                        assert!(head.contains(p.as_str()), "{label}: {p} not named: {head}");
                    }
                    let j = robodyn::report::base_parameters::json(&rep);
                    assert_eq!(j["comparison"]["arbiter"], "numeric");
                    assert_eq!(j["comparison"]["numeric_count"], nb.count());
                    assert_eq!(j["comparison"]["symbolic_count"], sb.count());
                    assert!(
                        robodyn::report::base_parameters::latex(&rep)
                            .contains("% THE METHODS DIFFER"),
                        "{label}"
                    );
                }
            }
            eprintln!(
                "{label}: numeric {} (inertial {} <= b_m {bm}), symbolic {}",
                nb.count(),
                inertial(&nb.base),
                sb.count()
            );
            // random parameters: both groupings reproduce the full model
            let k = random_parameters(&robot, &sel, 100 + seed);
            let err_n = check_against_idm(
                &format!("{label} numeric"),
                &robot,
                &k,
                &Grouping::numeric(&nb),
                &nb.base_values(&k),
                200 + seed,
            );
            let full = robot.with_standard_parameters(&k).unwrap();
            let kopt: Vec<Option<f64>> = k.iter().map(|&v| Some(v)).collect();
            let vs: Vec<f64> = sb
                .values(full.description(), &kopt)
                .into_iter()
                .map(|v| v.unwrap())
                .collect();
            let err_s = check_against_idm(
                &format!("{label} symbolic"),
                &robot,
                &k,
                &Grouping::symbolic(&sb, &robot),
                &vs,
                300 + seed,
            );
            eprintln!("  errors: numeric {err_n:e}, symbolic {err_s:e}");
        }
    }
}

#[test]
fn closed_sampler_rejects_a_tree_and_reports_unclosable_assemblies() {
    let tree = load("rx90.toml");
    let e = ClosedChainSampler::new(&tree).unwrap_err().to_string();
    assert!(e.contains("tree"), "{e}");
    // a closed robot sampled as a different robot is an error, not a wrong answer
    let sr = load("sr400.toml");
    let four = load("fourbar.toml");
    let mut s = ClosedChainSampler::new(&four).unwrap();
    assert!(s.sample(&sr, &mut rng(1)).is_err());
    // a four-bar whose ground link (5 m) is longer than the three others together never closes:
    // an error naming the robot, no panic
    let mut d = four.description().clone();
    d.frame_mut(3).d = robodyn::Expr::num(5.0);
    match Robot::new(d) {
        Err(e) => eprintln!("rejected at load: {e}"),
        Ok(bad) => {
            let e = ClosedChainSampler::new(&bad).unwrap_err().to_string();
            assert!(
                e.contains("planar four-bar") && e.contains("assembly"),
                "{e}"
            );
        }
    }
}

/// The diagnostic of a mismatch names the parameter: a grouping with one coefficient corrupted
/// (M2 in ZZR1 of the four-bar) is caught by the torque check and M2 is the worst column.
#[test]
fn a_wrong_grouping_is_named() {
    let robot = load("fourbar.toml");
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
    let nb = numeric(&robot, &sel, 3);
    let mut g = Grouping::numeric(&nb);
    let zz1 = nb
        .base
        .iter()
        .position(|&b| parameter_name(b) == "ZZ1")
        .unwrap();
    let m2 = nb
        .columns
        .iter()
        .position(|&c| parameter_name(c) == "M2")
        .unwrap();
    assert!(g.coef[(zz1, m2)].abs() > 1e-3, "M2 groups into ZZR1");
    g.coef[(zz1, m2)] *= 1.01;
    let k = random_parameters(&robot, &sel, 9);
    let values: Vec<f64> = (0..g.base.len())
        .map(|r| {
            g.columns
                .iter()
                .enumerate()
                .map(|(c, &col)| g.coef[(r, c)] * k[col])
                .sum()
        })
        .collect();
    let out = std::panic::catch_unwind(|| {
        check_against_idm("corrupted", &robot, &k, &g, &values, 4);
    });
    let msg = out.expect_err("the corrupted grouping must fail");
    let msg = msg.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(msg.contains("worst grouped parameter M2"), "{msg}");
}

/// The numerical result does not depend on the samples: for every closed robot, 8 seeds give the
/// same base set and the same grouped values. Value tolerance: 1e-8 relative, widened to
/// 1e-12 kappa with kappa = sigma_1 / sigma_r of the unit-column W (the rows carry ~1e-13 of
/// closure/rounding noise, amplified by kappa in beta): the 1-DOF spatial loop sampled over
/// +-1.5 rad has kappa ~ 1e5..1e6, so its beta is determined only to ~1e-7 while the torques are
/// still reproduced to 1e-13 (test above).
#[test]
fn closed_numeric_result_is_seed_independent() {
    let sigma = |nb: &NumericBase| nb.singular_values[nb.count() - 1];
    let kappa = |nb: &NumericBase| nb.singular_values[0] / sigma(nb);
    for file in CLOSED {
        let robot = load(file);
        let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::Actuated);
        let k = random_parameters(&robot, &sel, 5);
        let reference = numeric(&robot, &sel, 1000);
        let vr = reference.base_values(&k);
        for seed in 1001..1008u64 {
            let nb = numeric(&robot, &sel, seed);
            let label = format!("{file} seed {seed}");
            assert_eq!(names(&nb.base), names(&reference.base), "{label}");
            // a clear rank gap: the first dropped singular value is far below the tolerance, the last
            // kept one far above
            let next = nb.singular_values.get(nb.count()).copied().unwrap_or(0.0);
            assert!(
                next < 0.1 * nb.tolerance && sigma(&nb) > 100.0 * nb.tolerance,
                "{label}: rank gap {next:e} .. {:e}, tolerance {:e}",
                sigma(&nb),
                nb.tolerance
            );
            let (k1, k2) = (kappa(&nb), kappa(&reference));
            let tol = 1e-8f64.max(1e-12 * k1.max(k2));
            for (r, (a, b)) in nb.base_values(&k).iter().zip(&vr).enumerate() {
                let name = parameter_name(nb.base[r]);
                assert!(
                    (a - b).abs() <= tol * (1.0 + b.abs()),
                    "{label}: {name}: {a} vs {b} (tol {tol:e}, kappa {k1:e} / {k2:e})"
                );
            }
        }
    }
}
