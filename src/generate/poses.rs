//! Pose batches for experiments: B swept along an axis (the sliding spheres of §5.3.1), or
//! placed at random. A stays at the identity; a query sees only B's pose relative to A's.

use super::{GenerateError, Rng};
use crate::pose::Pose;
use nalgebra::{Matrix3, Vector3};
use std::fmt::Write as _;

/// The most poses one call makes: a million pose lines are about half a gigabyte of text.
pub const MAX_POSES: u64 = 1_000_000;

/// A model axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

impl Axis {
    /// The unit vector along the axis.
    pub fn unit(self) -> Vector3<f64> {
        match self {
            Axis::X => Vector3::x(),
            Axis::Y => Vector3::y(),
            Axis::Z => Vector3::z(),
        }
    }
}

/// How B is turned at each pose of a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepRotation {
    /// Not at all.
    Identity,
    /// By one uniformly random rotation drawn from the seed, the same at every pose.
    Fixed,
    /// By a fresh uniformly random rotation at every pose (§5.3.1: "a new random
    /// orientation at each step"), drawn in order from the seed.
    Fresh,
}

/// B translated along `axis` from `from` to `to` (inclusive, when a whole number of steps
/// reaches it) by `step`, turned as `rotation` says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// The direction of travel, in A's frame.
    pub axis: Axis,
    /// The first offset, model units.
    pub from: f64,
    /// The last offset, model units (at least `from`).
    pub to: f64,
    /// The distance between consecutive offsets, model units (greater than 0).
    pub step: f64,
    /// How B is turned.
    pub rotation: SweepRotation,
    /// The seed of the rotations.
    pub seed: u64,
}

/// A pose of A and a pose of B: one line of a pose file.
pub type PosePair = [Pose; 2];

/// The poses of a sweep: offset `i` is `from + i · step` (computed from `i`, so no error
/// accumulates), up to `to` plus a millionth of a step (so that 0 … 2 by 0.002 ends at 2
/// despite rounding). A is at the identity.
///
/// # Errors
///
/// [`GenerateError::Parameter`] for a `from` or `to` that is not finite, a `step` that is
/// not finite and greater than 0, or `to` below `from`; [`GenerateError::TooManyPoses`]
/// beyond [`MAX_POSES`].
///
/// # Examples
///
/// See the [module example](super).
pub fn sweep(s: &Sweep) -> Result<Vec<PosePair>, GenerateError> {
    for (name, value) in [("from", s.from), ("to", s.to)] {
        if !value.is_finite() {
            return Err(GenerateError::Parameter {
                name,
                value,
                expected: "finite",
            });
        }
    }
    if !(s.step.is_finite() && s.step > 0.0) {
        return Err(GenerateError::Parameter {
            name: "step",
            value: s.step,
            expected: "finite and greater than 0",
        });
    }
    if s.to < s.from {
        return Err(GenerateError::Parameter {
            name: "to",
            value: s.to,
            expected: "at least from",
        });
    }
    // Finite inputs with `to >= from`: at worst +∞ (a range beyond f64), never NaN.
    let steps = ((s.to - s.from) / s.step + 1e-6).floor();
    if steps >= MAX_POSES as f64 {
        return Err(GenerateError::TooManyPoses { count: steps + 1.0 });
    }
    let count = steps as u64 + 1;
    let fixed = Rng::new(s.seed).uniform_rotation();
    let mut rng = Rng::new(s.seed);
    let poses = (0..count)
        .map(|i| {
            let rotation = match s.rotation {
                SweepRotation::Identity => Matrix3::identity(),
                SweepRotation::Fixed => fixed,
                SweepRotation::Fresh => rng.uniform_rotation(),
            };
            let offset = s.from + i as f64 * s.step;
            posed(rotation, s.axis.unit() * offset)
        })
        .collect();
    Ok(poses)
}

/// `count` poses of B: a uniformly random rotation and a translation uniform in the ball
/// of `radius` about A's origin, drawn in order from `seed`. A is at the identity.
///
/// # Errors
///
/// [`GenerateError::Count`] for a `count` of 0, [`GenerateError::TooManyPoses`] beyond
/// [`MAX_POSES`], and [`GenerateError::Parameter`] for a radius that is not finite and at
/// least 0.
///
/// # Examples
///
/// See the [module example](super).
pub fn random_poses(count: u64, radius: f64, seed: u64) -> Result<Vec<PosePair>, GenerateError> {
    if count == 0 {
        return Err(GenerateError::Count {
            name: "count",
            count: 0,
            least: 1,
        });
    }
    if count > MAX_POSES {
        return Err(GenerateError::TooManyPoses {
            count: count as f64,
        });
    }
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(GenerateError::Parameter {
            name: "radius",
            value: radius,
            expected: "finite and at least 0",
        });
    }
    let mut rng = Rng::new(seed);
    Ok((0..count)
        .map(|_| {
            let rotation = rng.uniform_rotation();
            posed(rotation, rng.in_ball(radius))
        })
        .collect())
}

/// A at the identity, B at `rotation` and `translation`. The rotations made here are
/// orthonormal to about 1e-16 and the translations finite, which `Pose::new` accepts.
fn posed(rotation: Matrix3<f64>, translation: Vector3<f64>) -> PosePair {
    let b = Pose::new(rotation, translation).unwrap_or_default();
    [Pose::identity(), b]
}

/// A pose pair as one line of a pose file: A's 12 numbers then B's (rotation row by row,
/// then translation), each printed with the fewest digits that read back exactly.
pub fn pose_line(pair: &PosePair) -> String {
    let mut line = String::new();
    for value in pair.iter().flat_map(Pose::row_major) {
        if !line.is_empty() {
            line.push(' ');
        }
        // Writing to a String cannot fail.
        let _ = write!(line, "{value:?}");
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    fn offsets(s: &Sweep) -> Vec<f64> {
        sweep(s)
            .unwrap()
            .iter()
            .map(|[_, b]| b.translation_vector().x)
            .collect()
    }

    #[test]
    fn a_sweep_reaches_its_end_despite_rounding_and_computes_each_offset_afresh() {
        let s = Sweep {
            axis: Axis::X,
            from: 0.0,
            to: 2.0,
            step: 0.002,
            rotation: SweepRotation::Identity,
            seed: 1,
        };
        let x = offsets(&s);
        assert_eq!(x.len(), 1001);
        assert_eq!(x[1000], 2.0);
        assert_eq!(x[3], 3.0 * 0.002);
        let short = offsets(&Sweep { to: 1.9999, ..s });
        assert_eq!(short.len(), 1000);
    }

    #[test]
    fn sweep_rotations_are_none_one_or_fresh_and_replay_from_the_seed() {
        let base = Sweep {
            axis: Axis::Z,
            from: -1.0,
            to: 1.0,
            step: 0.5,
            rotation: SweepRotation::Fixed,
            seed: 9,
        };
        let fixed = sweep(&base).unwrap();
        assert!(fixed
            .windows(2)
            .all(|w| w[0][1].rotation() == w[1][1].rotation()));
        assert_ne!(*fixed[0][1].rotation(), Matrix3::identity());
        assert_eq!(
            fixed[4][1].translation_vector(),
            &Vector3::new(0.0, 0.0, 1.0)
        );
        let fresh = sweep(&Sweep {
            rotation: SweepRotation::Fresh,
            ..base
        })
        .unwrap();
        assert!(fresh
            .windows(2)
            .all(|w| w[0][1].rotation() != w[1][1].rotation()));
        assert_eq!(
            fresh,
            sweep(&Sweep {
                rotation: SweepRotation::Fresh,
                ..base
            })
            .unwrap()
        );
        let none = sweep(&Sweep {
            rotation: SweepRotation::Identity,
            ..base
        })
        .unwrap();
        assert!(none
            .iter()
            .all(|[a, b]| *b.rotation() == Matrix3::identity() && *a == Pose::identity()));
    }

    #[test]
    fn pose_lines_read_back_to_the_same_poses() {
        for pair in random_poses(50, 3.0, 4).unwrap() {
            let line = pose_line(&pair);
            let values: Vec<f64> = line.split(' ').map(|w| w.parse().unwrap()).collect();
            assert_eq!(values.len(), 24);
            assert_eq!(Pose::from_row_major(&values[..12]).unwrap(), pair[0]);
            assert_eq!(Pose::from_row_major(&values[12..]).unwrap(), pair[1]);
            assert!(pair[1].translation_vector().norm() <= 3.0);
        }
    }

    #[test]
    fn generators_refuse_what_they_cannot_make() {
        let s = Sweep {
            axis: Axis::Y,
            from: 0.0,
            to: 1.0,
            step: 0.1,
            rotation: SweepRotation::Identity,
            seed: 0,
        };
        assert!(sweep(&Sweep { step: 0.0, ..s }).is_err());
        assert!(sweep(&Sweep {
            step: f64::NAN,
            ..s
        })
        .is_err());
        assert!(sweep(&Sweep { to: -1.0, ..s }).is_err());
        assert!(sweep(&Sweep {
            from: f64::NEG_INFINITY,
            ..s
        })
        .is_err());
        assert!(matches!(
            sweep(&Sweep { step: 1e-9, ..s }),
            Err(GenerateError::TooManyPoses { .. })
        ));
        assert!(random_poses(MAX_POSES + 1, 1.0, 0).is_err());
        assert!(random_poses(1, -1.0, 0).is_err());
        assert!(random_poses(0, 1.0, 0).is_err());
    }
}
