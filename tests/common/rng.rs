//! The tests' seeded generator is the library's ([`obbtree::generate::Rng`]): the same
//! seed gives the same numbers on every machine, so a failing case can be replayed. Its
//! sequence is pinned by `tests/it/distance_work.rs`, whose poses come from
//! [`seeded_rotation`]: changing the generator changes those counts.

use nalgebra::Matrix3;
pub use obbtree::generate::Rng;

/// The Euler-angle rotation of a fresh generator seeded with `seed` (the pinned tests'
/// poses).
pub fn seeded_rotation(seed: u64) -> Matrix3<f64> {
    Rng::new(seed).euler_rotation()
}
