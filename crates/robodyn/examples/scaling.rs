//! How the cost of loading and of code generation grows with the size of a robot (issue 13's
//! cost table): a serial chain of n revolute links (alternating twists, numeric geometry,
//! symbolic inertial parameters), written as a TOML file, read back, and its inverse (and, up to
//! 100 links, direct) dynamic model generated as C.
//!
//! ```text
//!  cargo run --release -p robodyn --example scaling [-- 10 50 100 200 500 2000]
//! ```
//!
//! Prints one row per size: file size, load time, generation times and operation counts, and the
//! ratio of each time to the previous row's (linear growth gives the ratio of the sizes).

use robodyn::codegen::{generate_with_progress, GenOptions, ModelKind};
use robodyn::io::toml_format;
use robodyn_symbolic::{emit, Lang};
use std::time::Instant;

/// The TOML text of a serial chain of `n` links.
fn chain(n: usize) -> String {
    let mut s = format!("name = \"chain{n}\"\nnl = {n}\ngravity = [0, 0, -9.81]\n");
    for j in 1..=n {
        let alpha = ["0", "\"pi/2\"", "\"-pi/2\""][j % 3];
        s += &format!(
            "\n[[frame]]\nj = {j}\nant = {}\nsigma = 0\nalpha = {alpha}\nd = {}\nr = {}\n",
            j - 1,
            0.1 + 0.01 * (j % 7) as f64,
            0.05 * (j % 4) as f64
        );
    }
    for j in 1..=n {
        let m = 1.0 + (j % 5) as f64;
        s += &format!(
            "\n[[link]]\nj = {j}\nXX = {}\nYY = {}\nZZ = {}\nXY = 0.001\nMX = {}\nMZ = {}\nM = {m}\n\
             IA = 0.01\nFV = 0.1\nFS = 0.05\n",
            0.1 * m,
            0.12 * m,
            0.09 * m,
            0.05 * m,
            0.02 * m
        );
    }
    s
}

fn seconds(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("sizes are numbers of links"))
        .collect();
    let sizes = if sizes.is_empty() {
        vec![10, 50, 100, 200, 500, 2000]
    } else {
        sizes
    };
    println!(
        "| links | TOML size | load | ratio | generate idm (C) | ratio | idm ops (mul/add) | generate ddm (C) | ddm ops |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut last_load, mut last_idm) = (None::<f64>, None::<f64>);
    for n in sizes {
        let text = chain(n);
        let mut desc = None;
        let load = seconds(|| {
            desc = Some(
                toml_format::parse_description(&text, Some("chain.toml"))
                    .unwrap()
                    .0,
            )
        });
        let desc = desc.unwrap();
        let gen = |model| {
            let mut code = String::new();
            let mut ops = Default::default();
            let t = seconds(|| {
                let opt = GenOptions {
                    model,
                    ..GenOptions::default()
                };
                // SCALING_STAGES=1: the time of each stage on standard error
                let stages = std::env::var_os("SCALING_STAGES").is_some();
                let start = Instant::now();
                let mut report = |what: &str| {
                    if stages {
                        eprintln!(
                            "  {n} links, {:>7.3} s: {what}",
                            start.elapsed().as_secs_f64()
                        );
                    }
                };
                let p = generate_with_progress(&desc, &opt, &mut report).unwrap();
                ops = p.count();
                report("emitting C");
                code = emit(&p, Lang::C);
                report("done");
            });
            (t, ops, code.len())
        };
        let (idm, idm_ops, _) = gen(ModelKind::Idm);
        let ddm = (n <= 100).then(|| gen(ModelKind::Ddm));
        let ratio = |now: f64, before: Option<f64>| {
            before.map_or("".to_string(), |b| format!("x{:.1}", now / b))
        };
        println!(
            "| {n} | {} kB | {:.3} s | {} | {:.2} s | {} | {}/{} | {} | {} |",
            text.len() / 1000,
            load,
            ratio(load, last_load),
            idm,
            ratio(idm, last_idm),
            idm_ops.mul,
            idm_ops.add,
            ddm.as_ref()
                .map_or("-".to_string(), |(t, _, _)| format!("{t:.2} s")),
            ddm.as_ref()
                .map_or("-".to_string(), |(_, o, _)| format!("{}/{}", o.mul, o.add)),
        );
        last_load = Some(load);
        last_idm = Some(idm);
    }
}
