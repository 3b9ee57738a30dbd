//! The timing protocol of the Rust peers (`examples/peer_timing.rs`, `cg_timing.rs`), the same as
//! `pinocchio_peer.cpp` and `cg_timing.c`: a sample times loops over all items, repeated so that
//! it lasts about `target_us` microseconds; prints `time <name> <median ns per call>`.
//! `PEERS_ONLY=name,name` times only those (for profiling one algorithm under perf/callgrind);
//! `PEERS_REPS=R` fixes the repetitions per sample (counting cycles or instructions per call:
//! the difference of two runs with different R, divided by the difference of the calls).

use std::time::Instant;

pub fn time<S>(name: &str, items: &[S], samples: usize, target_us: f64, mut f: impl FnMut(&S)) {
    if let Ok(only) = std::env::var("PEERS_ONLY") {
        if !only.split(',').any(|o| o == name) {
            return;
        }
    }
    let mut pass = || items.iter().for_each(&mut f);
    pass();
    let t0 = Instant::now();
    pass();
    let one = t0.elapsed().as_secs_f64() * 1e6;
    let reps = match std::env::var("PEERS_REPS") {
        Ok(r) => r.parse().expect("PEERS_REPS: a number of repetitions"),
        Err(_) => ((target_us / one.max(1e-3)) as usize).max(1),
    };
    let mut ns: Vec<f64> = (0..samples)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                pass();
            }
            t.elapsed().as_secs_f64() * 1e9 / (reps * items.len()) as f64
        })
        .collect();
    ns.sort_by(f64::total_cmp);
    println!("time {name} {:.1}", ns[ns.len() / 2]);
}
