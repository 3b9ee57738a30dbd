// Robots of the generated-code bench and of the codegen tests (shared with `include!`).

/// The Acma SR400 bundled in `robots/sr400.toml`.
#[allow(dead_code)]
pub fn sr400_description() -> robodyn::RobotDescription {
    robodyn::io::load_description(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/sr400.toml"
    )))
    .expect("robots/sr400.toml loads")
}

/// Stäubli RX-90 geometry (as robots/rx90.toml): alpha = {0, pi/2, 0, -pi/2, pi/2, -pi/2}, d3 = D3,
/// r4 = RL4; inertial parameters of a random physically consistent robot (fixed seed 90), rotor
/// inertia and friction on every joint.
#[allow(dead_code)]
pub fn rx90_description() -> robodyn::RobotDescription {
    use robodyn::Expr;
    let mut d = robodyn::RobotDescription::new("RX-90", 6, 6);
    let alpha = ["0", "pi/2", "0", "-pi/2", "pi/2", "-pi/2"];
    for j in 1..=6 {
        d.frame_mut(j).alpha = Expr::parse(alpha[j - 1]).unwrap();
    }
    d.frame_mut(3).d = Expr::symbol("D3");
    d.frame_mut(4).r = Expr::symbol("RL4");
    d.symbols.insert("D3".into(), 0.45);
    d.symbols.insert("RL4".into(), 0.45);
    d.symbols.insert("G3".into(), 9.81);
    d.gravity = [Expr::zero(), Expr::zero(), Expr::parse("-G3").unwrap()];
    let mut r = robodyn_testing::rng(90);
    for j in 1..=6 {
        let p = robodyn_testing::random_inertial(&mut r);
        let l = d.link_mut(j);
        for (k, v) in p.iter().enumerate() {
            l.params[k] = Expr::num(*v);
        }
        l.params[10] = Expr::num(0.3);
        l.params[11] = Expr::num(0.5);
        l.params[12] = Expr::num(0.8);
    }
    d
}

/// The planar five-bar bundled in `robots/fivebar.toml` (closed, G depending on q).
#[allow(dead_code)]
pub fn fivebar_description() -> robodyn::RobotDescription {
    robodyn::io::load_description(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/fivebar.toml"
    )))
    .expect("robots/fivebar.toml loads")
}

/// The generated source of the bench: numeric values substituted, all options default.
#[allow(dead_code)]
pub fn bench_source(
    desc: &robodyn::RobotDescription,
    name: &str,
    model: robodyn::codegen::ModelKind,
) -> String {
    let opt = robodyn::codegen::GenOptions {
        model,
        numeric: true,
        name: Some(name.to_string()),
        ..Default::default()
    };
    let prog = robodyn::codegen::generate(desc, &opt).expect("generates");
    robodyn_symbolic::emit(&prog, robodyn_symbolic::Lang::Rust)
}
