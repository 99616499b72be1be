//! The one seeded random generator of obbtree's experiments and tests: the same seed gives
//! the same numbers on every machine and in every version, so a pose file or a failing
//! test can be regenerated exactly, and nothing depends on another crate's generator
//! staying the same.
//!
//! xorshift64 (13, 7, 17) on a seed spread by the golden ratio: plenty for sampling poses
//! and test inputs, and not for cryptography. Its sequence is pinned by the tests whose
//! work counts come from its poses (`tests/it/distance_work.rs`): changing it changes them.

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

/// A seeded xorshift64 generator.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (any value). The seed is spread by the golden ratio and made
    /// odd; seed 0, which that would leave as state 1 (whose first numbers are all near 0),
    /// starts from the golden ratio's bits instead.
    pub fn new(seed: u64) -> Rng {
        let spread = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        Rng(if spread == 0 {
            0x9e37_79b9_7f4a_7c15 ^ 0xa5a5_a5a5_a5a5_a5a5
        } else {
            spread
        } | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        let n = n as u64;
        self.next_u64().checked_rem(n).unwrap_or(0) as usize
    }

    /// Uniform in `[0, 1)`: the top 53 bits, so every value is an exact f64.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[-1, 1)`.
    pub fn signed(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }

    /// A rotation drawn uniformly over all rotations (Shoemake's unit quaternion from
    /// three uniform numbers, "Uniform random rotations", Graphics Gems III): every
    /// orientation equally likely, as the dissertation's "random rotations" are.
    pub fn uniform_rotation(&mut self) -> Matrix3<f64> {
        let tau = std::f64::consts::TAU;
        let (u1, u2, u3) = (self.unit(), self.unit(), self.unit());
        let (r1, r2) = ((1.0 - u1).sqrt(), u1.sqrt());
        let q = Quaternion::new(
            r2 * (tau * u3).cos(),
            r1 * (tau * u2).sin(),
            r1 * (tau * u2).cos(),
            r2 * (tau * u3).sin(),
        );
        *UnitQuaternion::from_quaternion(q)
            .to_rotation_matrix()
            .matrix()
    }

    /// A rotation from three uniform Euler angles: not uniform over rotations (it favours
    /// some), but it turns every axis. Kept because the pinned work counts of the tests
    /// were measured at its poses.
    pub fn euler_rotation(&mut self) -> Matrix3<f64> {
        let tau = std::f64::consts::TAU;
        let (a, b, c) = (self.unit() * tau, self.unit() * tau, self.unit() * tau);
        *Rotation3::from_euler_angles(a, b, c).matrix()
    }

    /// A point drawn uniformly from the ball of `radius` about the origin (by rejection
    /// from the enclosing cube: about 1.9 draws of three numbers on average).
    pub fn in_ball(&mut self, radius: f64) -> Vector3<f64> {
        loop {
            let p = Vector3::new(self.signed(), self.signed(), self.signed());
            if p.norm_squared() <= 1.0 {
                return p * radius;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_rotations_are_rotations_and_spread_evenly() {
        let mut rng = Rng::new(7);
        let n = 20_000;
        // A uniform rotation maps x to a uniform point of the sphere: the mean is near 0
        // and each coordinate's mean square near 1/3.
        let (mut sum, mut squares) = (Vector3::zeros(), Vector3::zeros());
        for _ in 0..n {
            let r = rng.uniform_rotation();
            assert!((r.transpose() * r - Matrix3::identity()).abs().max() < 1e-14);
            assert!((r.determinant() - 1.0).abs() < 1e-14);
            let x = r * Vector3::x();
            sum += x;
            squares += x.component_mul(&x);
        }
        let (mean, mean_square) = (sum / n as f64, squares / n as f64);
        assert!(mean.abs().max() < 0.02, "{mean:?}");
        assert!(
            (mean_square.add_scalar(-1.0 / 3.0)).abs().max() < 0.02,
            "{mean_square:?}"
        );
    }

    #[test]
    fn seed_zero_starts_as_well_mixed_as_any_other() {
        let first = Rng::new(0).unit();
        assert!((0.001..0.999).contains(&first), "{first}");
        assert_ne!(Rng::new(0).next_u64(), Rng::new(1).next_u64());
    }

    #[test]
    fn points_in_a_ball_stay_inside_and_fill_it() {
        let mut rng = Rng::new(3);
        let n = 20_000;
        let inner = (0..n)
            .map(|_| rng.in_ball(2.0).norm())
            .inspect(|&r| assert!(r <= 2.0))
            .filter(|&r| r <= 1.0)
            .count();
        // A uniform ball holds 1/8 of its points within half its radius.
        let share = inner as f64 / n as f64;
        assert!((share - 0.125).abs() < 0.01, "{share}");
    }
}
