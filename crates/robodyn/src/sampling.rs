//! The library's random samples: one seeded generator for every algorithm that draws states
//! (the numerical base parameters, the closed-chain start search, the customized models'
//! constant-rotation detection, the identification's sampled states and excitation).
//!
//! Fixed seeds make every result reproducible: the same robot and options give the same samples,
//! hence the same base parameters and the same excitation. The tests' random robots live in the
//! separate `robodyn-testing` crate, which draws from the same kind of generator.

use rand::SeedableRng;

/// The generator of the library's samples (ChaCha8: portable, the same stream on every platform).
pub type SampleRng = rand_chacha::ChaCha8Rng;

/// The generator seeded with `seed`.
pub fn rng(seed: u64) -> SampleRng {
    SampleRng::seed_from_u64(seed)
}
