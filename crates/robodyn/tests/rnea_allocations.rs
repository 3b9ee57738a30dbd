//! `rnea` allocates nothing once its workspace is built: a counting global allocator (counting
//! only on the calling thread, so the test harness's own threads do not interfere).

use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::testing::{self, random_state, random_tree, TreeOptions};
use robodyn::Workspace;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::PathBuf;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // try_with: the thread-local may already be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn rnea_allocates_nothing_after_the_workspace_is_built() {
    let sr400 = robodyn::io::load(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml"),
    )
    .unwrap();
    let mut rng = testing::rng(5);
    let mut robots = vec![sr400];
    for n in [2, 13, 30] {
        robots.push(random_tree(&mut rng, n, &TreeOptions::default()));
    }
    for robot in &robots {
        let n = robot.nl();
        let states: Vec<_> = (0..20).map(|_| random_state(&mut rng, n)).collect();
        let mut ws = Workspace::new(robot.numeric());
        let mut tau = vec![0.0; n];
        // The counter sees this thread's allocations: one Vec proves it counts.
        let before = allocations();
        let probe = vec![1u8; 16];
        assert_eq!(allocations(), before + 1, "the counting allocator counts");
        drop(probe);
        let before = allocations();
        let mut checksum = 0.0;
        for _ in 0..50 {
            for s in &states {
                rnea(robot.numeric(), &mut ws, &s[0], &s[1], &s[2], &mut tau);
                checksum += tau[n - 1];
            }
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{}: rnea allocated {} times in 1000 calls",
            robot.name(),
            after - before
        );
    }
}
