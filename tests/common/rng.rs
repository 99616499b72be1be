//! The one seeded random generator of the tests: the same seed gives the same numbers on
//! every machine, so a failing case can be replayed, and no test depends on a crate's
//! generator staying the same across versions.
//!
//! xorshift64 (13, 7, 17) on a seed spread by the golden ratio: plenty for sampling test
//! inputs. Its sequence is pinned by `tests/distance_work.rs`, whose poses come from
//! [`seeded_rotation`]: changing the generator changes those counts.

use nalgebra::{Matrix3, Rotation3};

/// A seeded xorshift generator.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (any value, 0 included: the state is made odd, never 0).
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A number in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// Uniform in `[0, 1)`: the top 53 bits, so every value is an exact f64.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[-1, 1)`.
    pub fn signed(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }

    /// A rotation from three uniform Euler angles (not uniform over rotations, but it
    /// turns every axis, which is what the scenes need).
    pub fn rotation(&mut self) -> Matrix3<f64> {
        let tau = std::f64::consts::TAU;
        let (a, b, c) = (self.unit() * tau, self.unit() * tau, self.unit() * tau);
        *Rotation3::from_euler_angles(a, b, c).matrix()
    }
}

/// The rotation of a fresh generator seeded with `seed`.
pub fn seeded_rotation(seed: u64) -> Matrix3<f64> {
    Rng::new(seed).rotation()
}
