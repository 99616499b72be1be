//! The oriented box of the compact layout: 28 bytes instead of [`Obb<f32>`]'s 60, for trees
//! shipped where size matters more than query time.

use super::pair::Guard;
use super::{BoundingVolume, BvDefect, BvKind, Layout, Obb};
use crate::pose::Pose;
use crate::real::Real;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// An oriented box stored in 28 bytes: the centre in f32, the frame as a quantised unit
/// quaternion, the half-widths as bfloat16 rounded up.
///
/// Every use decodes it ([`CompactObb::decode`]) into the [`Obb<f32>`] it stands for and
/// runs that box's tests, so the two layouts answer every query alike; a compact box is a
/// little larger than the fitted one (its frame is the quantised one, its half-widths
/// rounded up to 8 significant bits), which costs some more box tests.
///
/// The builder measures the box along the *decoded* frame, so the decoded box contains the
/// node's vertices exactly as a plain box does (the containment invariant of the format).
///
/// # Memory Layout
///
/// `#[repr(C)]`, little-endian: `center: f32[3]` (model frame), `rotation: i16[4]` (the
/// quaternion `w, x, y, z`, each component times 32767, rounded to nearest; not necessarily
/// of unit length after rounding: the decoder normalises), `half: u16[3]` (the upper 16
/// bits of the f32 half-widths, rounded up), 2 bytes of zero padding.
#[derive(Clone, Copy, Debug, PartialEq, FromBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct CompactObb {
    /// Box centre, model frame.
    pub center: [f32; 3],
    /// The rotation whose columns are the box axes (axis 0 of greatest spread), as a
    /// quaternion `w, x, y, z`, each component times 32767.
    pub rotation: [i16; 4],
    /// Half-widths along the axes (model units, non-negative), as bfloat16 bit patterns.
    pub half: [u16; 3],
    /// Zero.
    pad: u16,
}

/// The largest stored coordinate (absolute) a compact tree may hold: its boxes are then at
/// most √3 times that wide, within bfloat16's largest finite value (3.39e38).
pub const COMPACT_COORDINATE_LIMIT: f64 = 1e38;

/// What a quaternion component is multiplied by before it is rounded to an `i16`.
pub const QUATERNION_SCALE: f64 = 32767.0;

impl CompactObb {
    /// The box it stands for: the frame decoded and rounded to f32 rows exactly as the
    /// builder rounded it when it measured the box, the half-widths widened to f32.
    #[inline]
    pub fn decode(&self) -> Obb<f32> {
        let frame = decode_frame(self.rotation);
        let [c0, c1, c2]: [[f64; 3]; 3] = frame.into();
        Obb {
            // The rounding of `Obb::<f32>::enclose`, which measured the box along these rows.
            axes: [c0, c1, c2].map(|column| column.map(f32::from_f64_nearest)),
            center: self.center,
            half: self.half.map(bf16_to_f32),
        }
    }

    /// The compact form of `obb`, whose frame must be [`decode_frame`] of `rotation`.
    fn encode(obb: &Obb<f32>, rotation: [i16; 4]) -> CompactObb {
        CompactObb {
            center: obb.center,
            rotation,
            half: obb.half.map(bf16_up),
            pad: 0,
        }
    }

    /// Encodes the frame, and measures `enclose` along the frame the reader will decode.
    fn along_quantised(frame: &Matrix3<f64>, enclose: impl Fn(&Matrix3<f64>) -> Obb<f32>) -> Self {
        let rotation = quantise_frame(frame);
        CompactObb::encode(&enclose(&decode_frame(rotation)), rotation)
    }
}

/// The quaternion of the rotation whose columns are `frame`'s, scaled and rounded. A frame
/// of determinant −1 has its third column negated first (a box is symmetric, so the sign of
/// an axis does not matter).
fn quantise_frame(frame: &Matrix3<f64>) -> [i16; 4] {
    let mut m = *frame;
    if m.determinant() < 0.0 {
        m.set_column(2, &(-m.column(2)));
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    // Saturating casts of values in [-32767, 32767]. NaN, from a degenerate frame, is 0:
    // the zero quaternion decodes to the identity frame, along which the box is measured.
    [q.w, q.i, q.j, q.k].map(|c| (c * QUATERNION_SCALE).round() as i16)
}

/// The rotation matrix of the quantised quaternion `q`: its columns are the box axes.
///
/// The builder rounds unit quaternions, so `|q|²` is within about 1e-4 of
/// [`QUATERNION_SCALE`]² and `2 / |q|²` is taken to first order about it (a relative error
/// of about 1e-8, far inside the frames' tolerance): multiplications only, where a division
/// would add its latency to every box test. A quaternion far from that length (a damaged,
/// unverified file) gives a frame far from orthonormal, which `validate` rejects (the zero
/// quaternion gives the identity: i16 components keep every entry finite).
#[inline]
pub fn decode_frame(q: [i16; 4]) -> Matrix3<f64> {
    const INV_N0: f64 = 1.0 / (QUATERNION_SCALE * QUATERNION_SCALE);
    let [w, x, y, z] = q.map(f64::from);
    let s = 2.0 * INV_N0 * (2.0 - (w * w + x * x + y * y + z * z) * INV_N0);
    let (xx, yy, zz) = (s * x * x, s * y * y, s * z * z);
    let (xy, xz, yz) = (s * x * y, s * x * z, s * y * z);
    let (wx, wy, wz) = (s * w * x, s * w * y, s * w * z);
    Matrix3::new(
        1.0 - yy - zz,
        xy - wz,
        xz + wy,
        xy + wz,
        1.0 - xx - zz,
        yz - wx,
        xz - wy,
        yz + wx,
        1.0 - xx - yy,
    )
}

/// The smallest bfloat16 (upper half of an f32) not below `x` (`x ≥ 0`, finite).
fn bf16_up(x: f32) -> u16 {
    let bits = x.to_bits();
    // The shift leaves 16 bits; a positive float's bit patterns grow with its value, so
    // the next pattern up is the next value up.
    let truncated = (bits >> 16) as u16;
    if bits & 0xFFFF == 0 {
        truncated
    } else {
        truncated.saturating_add(1)
    }
}

/// The f32 value of a bfloat16 bit pattern (exact).
#[inline]
fn bf16_to_f32(h: u16) -> f32 {
    f32::from_bits(u32::from(h) << 16)
}

impl BoundingVolume for CompactObb {
    type Real = f32;
    const KIND: BvKind = BvKind::Obb;
    const NODE_LAYOUT: Layout = Layout::Compact;

    fn enclose(frame: &Matrix3<f64>, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self {
        Self::along_quantised(frame, |f| Obb::<f32>::enclose(f, positions, faces))
    }

    fn enclose_vertices(frame: &Matrix3<f64>, positions: &[[f64; 3]], vertices: &[u32]) -> Self {
        Self::along_quantised(frame, |f| {
            Obb::<f32>::enclose_vertices(f, positions, vertices)
        })
    }

    fn write_le(&self, out: &mut [u8]) {
        let mut bytes = [0u8; 28];
        let (center, rest) = bytes.split_at_mut(12);
        let (rotation, rest) = rest.split_at_mut(8);
        let (half, _pad) = rest.split_at_mut(6);
        for (o, v) in center.chunks_exact_mut(4).zip(self.center) {
            o.copy_from_slice(&v.to_le_bytes());
        }
        for (o, v) in rotation.chunks_exact_mut(2).zip(self.rotation) {
            o.copy_from_slice(&v.to_le_bytes());
        }
        for (o, v) in half.chunks_exact_mut(2).zip(self.half) {
            o.copy_from_slice(&v.to_le_bytes());
        }
        for (o, b) in out.iter_mut().zip(bytes) {
            *o = b;
        }
    }

    fn validate(&self) -> Result<(), BvDefect> {
        self.decode().validate()
    }

    fn contains(&self, p: [f64; 3], tolerance: f64) -> bool {
        self.decode().contains(p, tolerance)
    }

    #[inline]
    fn overlaps(&self, other: &Self, b_to_a: &Pose, guard: Guard) -> bool {
        self.decode().overlaps(&other.decode(), b_to_a, guard)
    }

    #[inline]
    fn overlaps_rewrapped(&self, other: &Self, b_to_a: &Pose, guard: Guard) -> bool {
        self.decode()
            .overlaps_rewrapped(&other.decode(), b_to_a, guard)
    }

    #[inline]
    fn distance_lower_bound_until(&self, other: &Self, b_to_a: &Pose, enough: f64) -> f64 {
        self.decode()
            .distance_lower_bound_until(&other.decode(), b_to_a, enough)
    }

    #[inline]
    fn distance_lower_bound_and_centres_until(
        &self,
        other: &Self,
        b_to_a: &Pose,
        enough: f64,
    ) -> (f64, f64) {
        self.decode()
            .distance_lower_bound_and_centres_until(&other.decode(), b_to_a, enough)
    }

    fn max_distance_upper_bound(&self, other: &Self, b_to_a: &Pose) -> f64 {
        self.decode()
            .max_distance_upper_bound(&other.decode(), b_to_a)
    }

    fn world_aabb(&self, pose: &Pose) -> super::Aabb<f64> {
        self.decode().world_aabb(pose)
    }

    fn center(&self) -> [f64; 3] {
        self.decode().center()
    }

    fn enclosing_ball(&self) -> ([f64; 3], f64) {
        self.decode().enclosing_ball()
    }

    fn diameter(&self) -> f64 {
        self.decode().diameter()
    }

    fn thickness(&self) -> f64 {
        self.decode().thickness()
    }

    fn volume(&self) -> f64 {
        self.decode().volume()
    }

    fn surface_area(&self) -> f64 {
        self.decode().surface_area()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bf16_rounds_up_and_round_trips() {
        for x in [0.0f32, 1.0, 0.1, 3.0e-20, 12345.678, f32::MIN_POSITIVE] {
            let h = bf16_to_f32(bf16_up(x));
            assert!(h >= x, "{x} -> {h}");
            assert!(h <= x * (1.0 + 1.0 / 128.0), "{x} -> {h}");
            assert_eq!(bf16_to_f32(bf16_up(h)), h);
        }
    }

    /// A compact box holds what it encloses and measures as the box it decodes to: centred
    /// in its world box, its ball and diameter reaching every enclosed point.
    #[test]
    fn compact_boxes_hold_and_measure_what_they_enclose() {
        let positions = [
            [0.1, -0.4, 2.0],
            [1.3, 0.2, 1.1],
            [-0.7, 0.9, 0.4],
            [0.5, 0.5, -1.2],
        ];
        let faces = [[0, 1, 2], [0, 2, 3], [1, 2, 3]];
        let frame = Rotation3::from_euler_angles(0.3, -1.2, 2.9).into_inner();
        let compact = CompactObb::enclose(&frame, &positions, &faces);
        let world = compact.world_aabb(&Pose::identity());
        let (ball, radius) = compact.enclosing_ball();
        let distance = |p: [f64; 3], q: [f64; 3]| crate::arr3::norm2(crate::arr3::sub(p, q)).sqrt();
        assert!(!compact.contains([3.0, 0.0, 0.0], 0.0));
        for p in positions {
            assert!(compact.contains(p, 0.0), "{p:?} outside {compact:?}");
            for ((lo, hi), x) in world.min.iter().zip(world.max).zip(p) {
                assert!(*lo <= x && x <= hi, "{p:?} outside {world:?}");
            }
            assert!(distance(ball, p) <= radius);
            for q in positions {
                assert!(distance(p, q) <= compact.diameter());
            }
        }
        for ((c, lo), hi) in compact.center().iter().zip(world.min).zip(world.max) {
            assert!(
                (c - (lo + hi) / 2.0).abs() < 1e-6,
                "{c} not centred in {world:?}"
            );
        }
        let decoded = compact.decode();
        assert_eq!(compact.volume(), decoded.volume());
        assert_eq!(compact.surface_area(), decoded.surface_area());
        assert_eq!(compact.thickness(), decoded.thickness());
        assert!(0.0 < compact.thickness() && compact.thickness() <= compact.diameter());
    }

    /// A damaged compact box is refused for what it decodes to: a negative or NaN
    /// half-width, or a quaternion far from unit length (its frame is not orthonormal).
    #[test]
    fn damaged_compact_boxes_are_refused() {
        let sound = CompactObb {
            center: [0.5, -1.0, 2.0],
            rotation: quantise_frame(&Rotation3::from_euler_angles(0.3, -1.2, 2.9).into_inner()),
            half: [1.0f32, 0.5, 0.25].map(bf16_up),
            pad: 0,
        };
        assert_eq!(sound.validate(), Ok(()));
        let negative = CompactObb {
            half: [1.0f32, -0.5, 0.25].map(|h| (h.to_bits() >> 16) as u16),
            ..sound
        };
        assert_eq!(negative.validate(), Err(BvDefect::NegativeExtent));
        let not_a_number = CompactObb {
            half: [0x7FC0, 0x3F80, 0x3F80],
            ..sound
        };
        assert_eq!(not_a_number.validate(), Err(BvDefect::NotFinite));
        let long = CompactObb {
            rotation: [32767, 32767, 32767, 0],
            ..sound
        };
        assert_eq!(long.validate(), Err(BvDefect::AxesNotOrthonormal));
    }

    #[test]
    fn frames_survive_quantisation() {
        let frames = [
            Matrix3::identity(),
            Rotation3::from_euler_angles(0.3, -1.2, 2.9).into_inner(),
            // Determinant −1: the third axis flips.
            Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        ];
        for frame in frames {
            let decoded = decode_frame(quantise_frame(&frame));
            for k in 0..3 {
                let (a, b) = (frame.column(k), decoded.column(k));
                // The same axis up to sign, within the quantisation's angle.
                assert!(a.dot(&b).abs() > 1.0 - 1e-8, "{frame} -> {decoded}");
            }
            let gram = decoded.transpose() * decoded;
            assert!((gram - Matrix3::identity()).abs().max() < 1e-7);
        }
    }

    /// The first-order normalisation keeps every rounded unit quaternion's frame far
    /// inside the f32 axis tolerance (1e-6) that the pair tests and `verify` allow.
    #[test]
    fn decoded_frames_are_orthonormal_far_inside_the_tolerance() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst = 0.0f64;
        for _ in 0..100_000 {
            let q = nalgebra::Quaternion::new(next(), next(), next(), next());
            if q.norm() < 1e-3 {
                continue;
            }
            let frame = UnitQuaternion::from_quaternion(q)
                .to_rotation_matrix()
                .into_inner();
            let decoded = decode_frame(quantise_frame(&frame));
            let gram = decoded.transpose() * decoded;
            worst = worst.max((gram - Matrix3::identity()).abs().max());
        }
        assert!(worst < 1e-7, "worst frame error {worst:e}");
    }
}
