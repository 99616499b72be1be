//! Stored precision: the scalar type of a file's vertices and bounding volumes.
//!
//! Queries always compute in f64 (poses are f64 whatever the stored precision); `Real` only
//! says how numbers are stored, and how f64 values are rounded into that storage so that
//! bounding volumes stay conservative.

use std::fmt::Debug;
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// The stored precision of a tree, as written in the file header.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// 32-bit IEEE floats: half the memory, about 7 significant digits.
    #[default]
    F32,
    /// 64-bit IEEE floats.
    F64,
}

impl Precision {
    /// Both precisions, smallest first.
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F64];

    /// The header tag: the size of one stored scalar in bytes (4 or 8).
    pub fn tag(self) -> u8 {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }

    /// Inverse of [`Precision::tag`].
    pub fn from_tag(tag: u8) -> Option<Precision> {
        match tag {
            4 => Some(Precision::F32),
            8 => Some(Precision::F64),
            _ => None,
        }
    }

    /// `"f32"` or `"f64"`, as used by the CLI.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }

    /// Inverse of [`Precision::name`].
    pub fn from_name(name: &str) -> Option<Precision> {
        Precision::ALL.into_iter().find(|p| p.name() == name)
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A stored scalar: `f32` or `f64` (sealed).
pub trait Real:
    sealed::Sealed
    + Copy
    + Debug
    + PartialOrd
    + Send
    + Sync
    + 'static
    + FromBytes
    + KnownLayout
    + Immutable
{
    /// Bytes that pad a tree node to a multiple of this type's alignment (see `bv::Node`).
    type NodePad: Copy
        + Debug
        + Default
        + Send
        + Sync
        + 'static
        + FromBytes
        + KnownLayout
        + Immutable;
    /// The header tag of this precision.
    const PRECISION: Precision;
    /// Round to the nearest representable value.
    fn from_f64_nearest(x: f64) -> Self;
    /// The smallest representable value `>= x` (for upper bounds that must stay conservative).
    fn from_f64_up(x: f64) -> Self;
    /// The largest representable value `<= x` (for lower bounds that must stay conservative).
    fn from_f64_down(x: f64) -> Self;
    /// Exact widening to f64.
    fn to_f64(self) -> f64;
    /// Narrowing to f32: exact for f32 (the f32 box test reads stored values through it).
    fn to_f32(self) -> f32;
    /// Writes the little-endian encoding into the first `size_of::<Self>()` bytes of `out`
    /// (fewer if `out` is shorter).
    fn write_le(self, out: &mut [u8]);
}

impl Real for f32 {
    type NodePad = [u8; 0];
    const PRECISION: Precision = Precision::F32;
    fn from_f64_nearest(x: f64) -> f32 {
        x as f32
    }
    // Whether rounding went the wrong way is a coin toss: selects, not branches (a
    // mispredicted branch here cost more than the rest of enclosing a leaf).
    fn from_f64_up(x: f64) -> f32 {
        let r = x as f32;
        std::hint::select_unpredictable(f64::from(r) < x, r.next_up(), r)
    }
    fn from_f64_down(x: f64) -> f32 {
        let r = x as f32;
        std::hint::select_unpredictable(f64::from(r) > x, r.next_down(), r)
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn to_f32(self) -> f32 {
        self
    }
    fn write_le(self, out: &mut [u8]) {
        for (o, b) in out.iter_mut().zip(self.to_le_bytes()) {
            *o = b;
        }
    }
}

impl Real for f64 {
    type NodePad = [u8; 4];
    const PRECISION: Precision = Precision::F64;
    fn from_f64_nearest(x: f64) -> f64 {
        x
    }
    fn from_f64_up(x: f64) -> f64 {
        x
    }
    fn from_f64_down(x: f64) -> f64 {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    // Rounds (used only by generic code that f64 volumes never reach).
    #[allow(clippy::cast_possible_truncation)]
    fn to_f32(self) -> f32 {
        self as f32
    }
    fn write_le(self, out: &mut [u8]) {
        for (o, b) in out.iter_mut().zip(self.to_le_bytes()) {
            *o = b;
        }
    }
}

/// Widens a stored point to f64.
pub fn point_to_f64<R: Real>(p: &[R; 3]) -> [f64; 3] {
    [p[0].to_f64(), p[1].to_f64(), p[2].to_f64()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directed_rounding_brackets_the_value() {
        for x in [0.1f64, -0.1, 1.0 / 3.0, -1e30, 1e-40, 0.0, 16777217.0] {
            assert!(f64::from(f32::from_f64_up(x)) >= x, "{x}");
            assert!(f64::from(f32::from_f64_down(x)) <= x, "{x}");
            assert!(
                f32::from_f64_up(x) - f32::from_f64_down(x)
                    <= f32::from_f64_up(x).abs() * 1.2e-7 + 1e-44
            );
        }
    }
}
