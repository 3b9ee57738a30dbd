//! robodyn's `generate --lang rust` output timed like cg_timing.c times the C (driven by
//! codegen.py; NOT run by CI; compiled with rustc directly, no crate):
//!
//!   RD_IDM=... RD_INERTIA=... RD_DDM=... RD_IDM_DERIVATIVES=... rustc -C opt-level=3 -C target-cpu=native cg_timing.rs
//!   (with median.rs beside it)
//!   cg_timing STATES RESULTS [samples] [target_us]
//!
//! Same STATES file and protocol as cg_timing.c; RESULTS lines `rs_rnea`, `rs_crba`, `rs_ddm`,
//! `rs_drnea` (the derivatives' three blocks, each row by row) in Pinocchio's order.

include!(env!("RD_IDM"));
include!(env!("RD_INERTIA"));
include!(env!("RD_DDM"));
include!(env!("RD_IDM_DERIVATIVES"));

use std::hint::black_box;
mod median;
use median::time;

struct States {
    nv: usize,
    rank: Vec<usize>,
    q: Vec<Vec<f64>>,
    qd: Vec<Vec<f64>>,
    qdd: Vec<Vec<f64>>,
    tau: Vec<Vec<f64>>,
}

fn read_states(path: &str) -> States {
    let text = std::fs::read_to_string(path).expect("states file");
    let mut it = text.split_whitespace();
    let mut next = || it.next().expect("truncated states file");
    let nv: usize = next().parse().unwrap();
    let nl: usize = next().parse().unwrap();
    let ns: usize = next().parse().unwrap();
    let idx: Vec<usize> = (0..nv).map(|_| next().parse().unwrap()).collect();
    let rank: Vec<usize> = (0..nv).map(|_| next().parse().unwrap()).collect();
    let mut st = States {
        nv,
        rank,
        q: vec![],
        qd: vec![],
        qdd: vec![],
        tau: vec![],
    };
    for _ in 0..ns {
        let mut parts = (0..4).map(|_| {
            let mut v = vec![0.0; nl];
            for &i in &idx {
                v[i] = next().parse().unwrap();
            }
            v
        });
        let (q, qd, qdd, tau) = (
            parts.next().unwrap(),
            parts.next().unwrap(),
            parts.next().unwrap(),
            parts.next().unwrap(),
        );
        st.q.push(q);
        st.qd.push(qd);
        st.qdd.push(qdd);
        st.tau.push(tau);
    }
    st
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let st = read_states(&args[1]);
    let samples: usize = args.get(3).map_or(21, |s| s.parse().unwrap());
    let target_us: f64 = args.get(4).map_or(400.0, |s| s.parse().unwrap());
    let (nv, ns) = (st.nv, st.q.len());
    let mut out = vec![0.0; 3 * nv * nv];
    let mut text = String::new();
    let put = |text: &mut String, tag: &str, v: &mut dyn Iterator<Item = f64>| {
        text.push_str(tag);
        for x in v {
            text.push_str(&format!(" {x:e}"));
        }
        text.push('\n');
    };
    let lower = |i: usize, j: usize| {
        let (r, c) = (st.rank[i].max(st.rank[j]), st.rank[i].min(st.rank[j]));
        r * (r + 1) / 2 + c
    };
    for s in 0..ns {
        rd_idm(&st.q[s], &st.qd[s], &st.qdd[s], &mut out);
        put(&mut text, "rs_rnea", &mut st.rank.iter().map(|&r| out[r]));
        rd_inertia(&st.q[s], &mut out);
        let m: Vec<f64> = (0..nv * nv).map(|k| out[lower(k / nv, k % nv)]).collect();
        put(&mut text, "rs_crba", &mut m.into_iter());
        rd_ddm(&st.q[s], &st.qd[s], &st.tau[s], &mut out);
        put(&mut text, "rs_ddm", &mut st.rank.iter().map(|&r| out[r]));
        rd_idm_derivatives(&st.q[s], &st.qd[s], &st.qdd[s], &mut out);
        let d: Vec<f64> = (0..3 * nv * nv)
            .map(|k| {
                let (b, i, j) = (k / (nv * nv), (k / nv) % nv, k % nv);
                out[b * nv * nv + st.rank[j] * nv + st.rank[i]]
            })
            .collect();
        put(&mut text, "rs_drnea", &mut d.into_iter());
    }
    std::fs::write(&args[2], text).expect("results file");
    let states: Vec<usize> = (0..ns).collect();
    time("rd_idm_rust", &states, samples, target_us, |&s| {
        rd_idm(black_box(&st.q[s]), &st.qd[s], &st.qdd[s], &mut out);
        black_box(&out);
    });
    time("rd_inertia_rust", &states, samples, target_us, |&s| {
        rd_inertia(black_box(&st.q[s]), &mut out);
        black_box(&out);
    });
    time("rd_ddm_rust", &states, samples, target_us, |&s| {
        rd_ddm(black_box(&st.q[s]), &st.qd[s], &st.tau[s], &mut out);
        black_box(&out);
    });
    time("rd_idm_derivatives_rust", &states, samples, target_us, |&s| {
        rd_idm_derivatives(black_box(&st.q[s]), &st.qd[s], &st.qdd[s], &mut out);
        black_box(&out);
    });
}
