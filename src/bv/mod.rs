//! Bounding volumes: the trait every tree node's volume implements, and the node record.
//!
//! Three volumes exist so the dissertation's comparisons can run on equal footing: the
//! oriented box ([`Obb`], the default), the axis-aligned box ([`Aabb`]) and the sphere
//! ([`Sphere`]). The builder splits every tree with the same rule whatever the volume, so
//! trees of different volume types over the same mesh have the same shape.

mod aabb;
mod ball;
mod compact;
mod obb;
pub mod pair;
mod pair_f32;
mod sphere;

pub use aabb::Aabb;
pub use compact::{CompactObb, COMPACT_COORDINATE_LIMIT};
pub use obb::Obb;
pub use sphere::Sphere;

use crate::arr3;
use crate::pose::Pose;
use crate::real::{Precision, Real};
use nalgebra::{Matrix3, Vector3};
use std::fmt::Debug;
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// Generic code run on a node type chosen at run time, from a [`NodeType`] read from a
/// header or made from options: the one dispatch idiom of the crate. [`dispatch`] holds the
/// one match over the node types, so adding one means adding its arm there.
pub trait VolumeVisitor {
    /// What the visit returns.
    type Output;
    /// Called once, with `B` the stored volume type (and through it the precision and
    /// layout).
    fn visit<B: BoundingVolume>(self) -> Self::Output;
}

/// Runs `visitor` with the volume type `node` stores (static dispatch: one match here, then
/// monomorphised code).
///
/// # Examples
///
/// ```
/// use obbtree::bv::{dispatch, BoundingVolume, BvKind, Layout, NodeType, VolumeVisitor};
/// use obbtree::real::Precision;
///
/// /// The size of one stored volume.
/// struct VolumeSize;
/// impl VolumeVisitor for VolumeSize {
///     type Output = usize;
///     fn visit<B: BoundingVolume>(self) -> usize {
///         std::mem::size_of::<B>()
///     }
/// }
///
/// let f32_box = dispatch(NodeType::plain(BvKind::Obb, Precision::F32), VolumeSize);
/// let f64_box = dispatch(NodeType::plain(BvKind::Obb, Precision::F64), VolumeSize);
/// assert_eq!(f64_box, 2 * f32_box);
/// let compact = NodeType::new(BvKind::Obb, Precision::F32, Layout::Compact)?;
/// assert!(dispatch(compact, VolumeSize) < f32_box / 2);
/// # Ok::<(), obbtree::bv::LayoutError>(())
/// ```
pub fn dispatch<V: VolumeVisitor>(node: NodeType, visitor: V) -> V::Output {
    match (node.layout, node.bv, node.precision) {
        // `NodeType::new` admits the compact layout for f32 boxes only.
        (Layout::Compact, _, _) => visitor.visit::<CompactObb>(),
        (Layout::Fast, BvKind::Obb, Precision::F32) => visitor.visit::<Obb<f32>>(),
        (Layout::Fast, BvKind::Obb, Precision::F64) => visitor.visit::<Obb<f64>>(),
        (Layout::Fast, BvKind::Aabb, Precision::F32) => visitor.visit::<Aabb<f32>>(),
        (Layout::Fast, BvKind::Aabb, Precision::F64) => visitor.visit::<Aabb<f64>>(),
        (Layout::Fast, BvKind::Sphere, Precision::F32) => visitor.visit::<Sphere<f32>>(),
        (Layout::Fast, BvKind::Sphere, Precision::F64) => visitor.visit::<Sphere<f64>>(),
    }
}

/// How a tree's node records are laid out, as written in the file header.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Layout {
    /// Each volume's scalars as they are: the fastest to query.
    #[default]
    Fast,
    /// Quantised boxes ([`CompactObb`], 32-byte nodes instead of 64), built with four faces
    /// per leaf by default ([`Layout::default_leaf_size`]): about a third of the bytes of a
    /// default fast tree on typical meshes, for slower queries. f32 oriented boxes only.
    Compact,
}

impl Layout {
    /// Both layouts, default first.
    pub const ALL: [Layout; 2] = [Layout::Fast, Layout::Compact];

    /// The header tag (0, 1).
    pub fn tag(self) -> u8 {
        match self {
            Layout::Fast => 0,
            Layout::Compact => 1,
        }
    }

    /// Inverse of [`Layout::tag`].
    pub fn from_tag(tag: u8) -> Option<Layout> {
        Layout::ALL.into_iter().find(|l| l.tag() == tag)
    }

    /// `"fast"` or `"compact"`, as used by the CLI.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Fast => "fast",
            Layout::Compact => "compact",
        }
    }

    /// Inverse of [`Layout::name`].
    pub fn from_name(name: &str) -> Option<Layout> {
        Layout::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The leaf size a build uses when none is asked for: 1 for the fast layout, where
    /// single-face leaves make the fastest queries; 4 for the compact one, where leaves of
    /// four faces take a third of the nodes, and the extra triangle tests cost less than
    /// the box tests (each decoding two boxes) they replace.
    pub fn default_leaf_size(self) -> u32 {
        match self {
            Layout::Fast => 1,
            Layout::Compact => 4,
        }
    }
}

/// What a tree's nodes store: the volume, its precision and the layout. Only combinations
/// that exist can be made, so [`dispatch`] always has a type to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NodeType {
    bv: BvKind,
    precision: Precision,
    layout: Layout,
}

impl NodeType {
    /// The node type of `bv` at `precision` in `layout`.
    ///
    /// # Errors
    ///
    /// [`LayoutError`] for the compact layout of anything but f32 oriented boxes.
    pub fn new(bv: BvKind, precision: Precision, layout: Layout) -> Result<NodeType, LayoutError> {
        if layout == Layout::Compact && (bv, precision) != (BvKind::Obb, Precision::F32) {
            return Err(LayoutError { bv, precision });
        }
        Ok(NodeType {
            bv,
            precision,
            layout,
        })
    }

    /// The node type of `bv` at `precision` in the fast layout (every combination exists).
    pub fn plain(bv: BvKind, precision: Precision) -> NodeType {
        NodeType {
            bv,
            precision,
            layout: Layout::Fast,
        }
    }

    /// The stored volume.
    pub fn bv(self) -> BvKind {
        self.bv
    }

    /// The stored precision: of the vertices, and of the volumes' scalars (the centres of
    /// compact boxes).
    pub fn precision(self) -> Precision {
        self.precision
    }

    /// The node layout.
    pub fn layout(self) -> Layout {
        self.layout
    }
}

/// `"obb f32"`, or `"obb f32 compact"` for the compact layout: how messages name a tree.
impl std::fmt::Display for NodeType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.bv.name(), self.precision.name())?;
        if self.layout != Layout::Fast {
            write!(f, " {}", self.layout.name())?;
        }
        Ok(())
    }
}

/// The node type volume `B` is stored as.
pub fn node_type_of<B: BoundingVolume>() -> NodeType {
    NodeType {
        bv: B::KIND,
        precision: <B::Real as Real>::PRECISION,
        layout: B::NODE_LAYOUT,
    }
}

/// A layout asked for a volume and precision it does not exist for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the compact layout stores f32 oriented boxes only, not {} {} trees (--bv obb --precision f32)", .bv.name(), .precision.name())]
pub struct LayoutError {
    /// The volume asked for.
    pub bv: BvKind,
    /// The precision asked for.
    pub precision: Precision,
}

/// Which bounding volume a tree stores, as written in the file header.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BvKind {
    /// Oriented bounding box, fitted to a covariance frame.
    #[default]
    Obb,
    /// Axis-aligned bounding box in the model frame.
    Aabb,
    /// Bounding sphere, centred on the box centre of the fitted frame.
    Sphere,
}

impl BvKind {
    /// All kinds, default first.
    pub const ALL: [BvKind; 3] = [BvKind::Obb, BvKind::Aabb, BvKind::Sphere];

    /// The header tag (1, 2, 3).
    pub fn tag(self) -> u8 {
        match self {
            BvKind::Obb => 1,
            BvKind::Aabb => 2,
            BvKind::Sphere => 3,
        }
    }

    /// Inverse of [`BvKind::tag`].
    pub fn from_tag(tag: u8) -> Option<BvKind> {
        BvKind::ALL.into_iter().find(|k| k.tag() == tag)
    }

    /// `"obb"`, `"aabb"` or `"sphere"`, as used by the CLI.
    pub fn name(self) -> &'static str {
        match self {
            BvKind::Obb => "obb",
            BvKind::Aabb => "aabb",
            BvKind::Sphere => "sphere",
        }
    }

    /// Inverse of [`BvKind::name`].
    pub fn from_name(name: &str) -> Option<BvKind> {
        BvKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// Why a stored volume is not well formed (found by `verify`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvDefect {
    /// A component is NaN or infinite.
    NotFinite,
    /// A half-width, radius, or `max - min` is negative.
    NegativeExtent,
    /// The stored axes are not orthonormal within the precision's tolerance.
    AxesNotOrthonormal,
}

impl std::fmt::Display for BvDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BvDefect::NotFinite => "a bounding-volume component is not finite",
            BvDefect::NegativeExtent => "a bounding-volume extent is negative",
            BvDefect::AxesNotOrthonormal => "the box axes are not orthonormal",
        })
    }
}

/// A bounding volume as stored in a tree node, in the model frame of its tree.
///
/// Implementations are `#[repr(C)]` plain data read zero-copy from mapped files, so any bit
/// pattern is a value: [`BoundingVolume::validate`] says whether it is a well-formed one.
pub trait BoundingVolume:
    Copy + Debug + Send + Sync + 'static + FromBytes + KnownLayout + Immutable
{
    /// The stored scalar type.
    type Real: Real;
    /// The header tag of this volume type.
    const KIND: BvKind;
    /// The node layout this type is stored in.
    const NODE_LAYOUT: Layout = Layout::Fast;

    /// The smallest volume of this type that contains every vertex of `faces`, given the
    /// fitted frame `axes` (orthonormal columns, greatest spread first; only the oriented box
    /// and the sphere use it). `positions` are the stored vertices widened to f64, so the
    /// result contains them exactly: every rounding to [`Self::Real`] is outward.
    fn enclose(axes: &Matrix3<f64>, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self;

    /// The same volume as [`BoundingVolume::enclose`] of any faces whose vertices are
    /// `vertices` (indices into `positions`; repeats allowed, out-of-range ones ignored):
    /// the volume depends only on the set of vertices, so a caller that has already found
    /// the distinct ones need not visit every corner of every face.
    fn enclose_vertices(axes: &Matrix3<f64>, positions: &[[f64; 3]], vertices: &[u32]) -> Self {
        let faces: Vec<[u32; 3]> = vertices.iter().map(|&v| [v, v, v]).collect();
        Self::enclose(axes, positions, &faces)
    }

    /// [`BoundingVolume::enclose_vertices`] along `axes` and along the model's own axes
    /// ([`model_axes_frame`] of the vertices), each with its frame: the builder keeps the
    /// smaller (`--model-axes`). The oriented box measures both in one pass over the
    /// vertices; this default takes three.
    fn enclose_vertices_fitted_and_aligned(
        axes: &Matrix3<f64>,
        positions: &[[f64; 3]],
        vertices: &[u32],
    ) -> [(Matrix3<f64>, Self); 2] {
        let (lo, hi) = arr3::bounds(listed_vertices(positions, vertices));
        let model = model_axes_frame(lo, hi);
        [
            (*axes, Self::enclose_vertices(axes, positions, vertices)),
            (model, Self::enclose_vertices(&model, positions, vertices)),
        ]
    }

    /// For sphere volumes, the sphere about the centre of the smallest ball containing
    /// `vertices` (`--sphere-fit minimal`: the dissertation compared boxes with such
    /// spheres); `None` for the other types.
    fn enclose_vertices_minimal_ball(_positions: &[[f64; 3]], _vertices: &[u32]) -> Option<Self> {
        None
    }

    /// Writes the little-endian bytes of this volume in on-disk field order into the first
    /// `size_of::<Self>()` bytes of `out` (fewer if `out` is shorter).
    fn write_le(&self, out: &mut [u8]);

    /// Checks the invariants a reader cannot assume of foreign bytes.
    fn validate(&self) -> Result<(), BvDefect>;

    /// Whether model-frame point `p` lies inside, allowing `tolerance` model units of slack.
    fn contains(&self, p: [f64; 3], tolerance: f64) -> bool;

    /// Whether this volume (model A's frame) and `other` (model B's frame, mapped into A's by
    /// `b_to_a`, the pose of B's frame in A's: [`Pose::relative`]) may intersect.
    /// Conservative: `false` only if they are certainly disjoint, given a `guard` that
    /// covers the models' coordinates ([`pair::Guard::for_models`]).
    fn overlaps(&self, other: &Self, b_to_a: &Pose, guard: pair::Guard) -> bool;

    /// [`BoundingVolume::overlaps`] as the dissertation's experiments tested boxes of
    /// simpler types: `other` re-wrapped in the smallest box aligned with this volume's
    /// frame, and the two compared on this volume's three axes only
    /// ([`pair::BoxPair::rewrapped_disjoint`]). Looser (more pairs pass) and cheaper; the
    /// same as `overlaps` for spheres.
    #[inline]
    fn overlaps_rewrapped(&self, other: &Self, b_to_a: &Pose, guard: pair::Guard) -> bool {
        self.overlaps(other, b_to_a, guard)
    }

    /// A lower bound on the distance between this volume and `other` (posed as in
    /// [`BoundingVolume::overlaps`]); 0 when they may overlap. The tightest this volume
    /// type gives: [`BoundingVolume::distance_lower_bound_until`] with no threshold.
    #[inline]
    fn distance_lower_bound(&self, other: &Self, b_to_a: &Pose) -> f64 {
        self.distance_lower_bound_until(other, b_to_a, f64::INFINITY)
    }

    /// A lower bound on the distance, as [`BoundingVolume::distance_lower_bound`], whose
    /// work may stop once it reaches `enough`: a traversal that prunes every pair whose
    /// bound reaches a threshold needs no tighter bound for those, and most pairs it tests
    /// are pruned by the cheapest terms. The result is either `>= enough` or the tightest
    /// bound.
    fn distance_lower_bound_until(&self, other: &Self, b_to_a: &Pose, enough: f64) -> f64;

    /// [`BoundingVolume::distance_lower_bound_until`] and the distance between the
    /// volumes' centres (model units of A), from one setup of the pair. A distance
    /// traversal chooses the child a dive continues with by both: the bound alone favours
    /// the larger volume, which reaches further, the centres say where the surfaces are.
    fn distance_lower_bound_and_centres_until(
        &self,
        other: &Self,
        b_to_a: &Pose,
        enough: f64,
    ) -> (f64, f64);

    /// An upper bound on the largest distance between a point of this volume and a point of
    /// `other` (posed as in [`BoundingVolume::overlaps`]).
    fn max_distance_upper_bound(&self, other: &Self, b_to_a: &Pose) -> f64;

    /// An axis-aligned box containing this volume once mapped by `pose` (a model's pose: the
    /// box is in world coordinates): the broad phase of scenes bounds each posed model by
    /// the world box of its root volume, with no traversal. Conservative: widened for the
    /// stored frame's error and for rounding.
    fn world_aabb(&self, pose: &Pose) -> Aabb<f64>;

    /// The volume's centre, model frame.
    fn center(&self) -> [f64; 3];

    /// A ball containing the volume: centre (model frame) and radius (model units), widened
    /// for the stored frame's error and for rounding. Testing two such balls costs a tenth
    /// of a box test, which is what a collision query culled at the roots needs.
    fn enclosing_ball(&self) -> ([f64; 3], f64);

    /// Largest distance between two points of the volume (model units).
    fn diameter(&self) -> f64;
    /// Smallest width of the volume (model units): a box's smallest side, a sphere's
    /// diameter. How flat a node's volume is (dissertation Fig. 5.17).
    fn thickness(&self) -> f64;
    /// Enclosed volume (cubic model units).
    fn volume(&self) -> f64;
    /// Surface area (square model units).
    fn surface_area(&self) -> f64;
}

/// One tree node as stored in the `nodes` section: a bounding volume and one packed 32-bit
/// reference to its children or faces (decoded only by [`crate::tree`]).
///
/// # Memory Layout
///
/// `#[repr(C)]`: the volume's fields, then `packed` (u32, little-endian), then zero padding up
/// to the scalar alignment (none for f32, 4 bytes for f64). Sizes: OBB 64 / 128 bytes (an f32
/// node is one cache line), AABB 28 / 56, sphere 20 / 40 (f32 / f64); a compact box 32.
#[derive(Clone, Copy, Debug, FromBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct Node<B: BoundingVolume> {
    /// The volume enclosing every vertex of every face below this node.
    pub bv: B,
    /// Packed child or face reference; see [`crate::tree::Encoding`].
    pub packed: u32,
    /// Zero padding to the scalar alignment.
    pad: <B::Real as Real>::NodePad,
}

impl<B: BoundingVolume> Node<B> {
    /// A node record from its volume and packed reference.
    pub fn new(bv: B, packed: u32) -> Self {
        Node {
            bv,
            packed,
            pad: Default::default(),
        }
    }

    /// The on-disk size of one node of this type, in bytes.
    pub const SIZE: usize = std::mem::size_of::<Self>();

    /// Writes the little-endian bytes of this node, padding included (zero), into the first
    /// [`Node::SIZE`] bytes of `out` (fewer if `out` is shorter). Written in place: a build
    /// writes one node per face and a half, and appending scalar by scalar to a buffer
    /// was a measurable share of a build.
    pub fn write_le(&self, out: &mut [u8]) {
        let (bv, rest) = out.split_at_mut(std::mem::size_of::<B>().min(out.len()));
        self.bv.write_le(bv);
        let (packed, pad) = rest.split_at_mut(4.min(rest.len()));
        for (o, b) in packed.iter_mut().zip(self.packed.to_le_bytes()) {
            *o = b;
        }
        let pad_len = Self::SIZE.saturating_sub(std::mem::size_of::<B>() + 4);
        pad.iter_mut().take(pad_len).for_each(|b| *b = 0);
    }
}

// The on-disk strides promised by the format spec (formats/obbt.md).
const _: () = {
    use std::mem::size_of;
    assert!(size_of::<Node<Obb<f32>>>() == 64);
    assert!(size_of::<Node<Obb<f64>>>() == 128);
    assert!(size_of::<Node<Aabb<f32>>>() == 28);
    assert!(size_of::<Node<Aabb<f64>>>() == 56);
    assert!(size_of::<Node<Sphere<f32>>>() == 20);
    assert!(size_of::<Node<Sphere<f64>>>() == 40);
    assert!(size_of::<Node<CompactObb>>() == 32);
};

/// The error bound of `dot(axis, p)` in f64 for axis components of magnitude at most 1:
/// a few units in the last place of `sum |p_j|`. Added to stored extents so containment
/// survives the rounding of the projections themselves.
pub(crate) fn projection_slack(l1_norm: f64) -> f64 {
    4.0 * f64::EPSILON * l1_norm
}

/// The model's own axes as a frame for points with componentwise extremes `lo` and `hi`:
/// unit columns, greatest extent first (ties in x, y, z order), right-handed, the same
/// conventions as a fitted frame.
pub fn model_axes_frame(lo: [f64; 3], hi: [f64; 3]) -> Matrix3<f64> {
    let [ex, ey, ez] = arr3::sub(hi, lo);
    let mut order = [(ex, 0usize), (ey, 1), (ez, 2)];
    // Greatest extent first; a stable sort, so equal extents keep x, y, z order.
    order.sort_by(|a, b| b.0.total_cmp(&a.0));
    let axis = |k: usize| {
        let mut v = Vector3::zeros();
        if let Some(c) = v.get_mut(k) {
            *c = 1.0;
        }
        v
    };
    let [(_, first), (_, second), _] = order;
    let (c0, c1) = (axis(first), axis(second));
    Matrix3::from_columns(&[c0, c1, c0.cross(&c1)])
}

/// Sum of absolute coordinates.
pub(crate) fn l1(p: &[f64; 3]) -> f64 {
    p[0].abs() + p[1].abs() + p[2].abs()
}

/// Every distinct-or-not vertex of `faces`, widened; the callers only take extrema over them.
pub(crate) fn face_vertices<'a>(
    positions: &'a [[f64; 3]],
    faces: &'a [[u32; 3]],
) -> impl Iterator<Item = &'a [f64; 3]> + Clone + 'a {
    faces
        .iter()
        .flatten()
        .filter_map(move |&v| positions.get(v as usize))
}

/// The positions of `vertices` (out-of-range indices skipped).
pub(crate) fn listed_vertices<'a>(
    positions: &'a [[f64; 3]],
    vertices: &'a [u32],
) -> impl Iterator<Item = &'a [f64; 3]> + Clone + 'a {
    vertices
        .iter()
        .filter_map(move |&v| positions.get(v as usize))
}

/// Whether all components are finite.
pub(crate) fn all_finite<R: Real>(values: &[R]) -> bool {
    values.iter().all(|v| v.to_f64().is_finite())
}

/// The world box of a box volume: centre `center` (model frame), axes the rows of `axes`,
/// half-widths `half`, mapped by `pose`. Each world extent is
/// `Σ_i h_i |(R a_i)_k|`; `frame_error` (how far the axes may be from orthonormal) widens
/// it by that share of the half-widths, and a few ulps of the magnitudes cover rounding.
pub(crate) fn posed_box_aabb(
    center: &Vector3<f64>,
    axes: &Matrix3<f64>,
    half: &Vector3<f64>,
    frame_error: f64,
    pose: &Pose,
) -> Aabb<f64> {
    let (rotation, translation) = (pose.rotation(), pose.translation_vector());
    let c = rotation * center + translation;
    // Column i of `world_axes` is axis i in the world.
    let world_axes = rotation * axes.transpose();
    let extent = world_axes.abs() * half;
    let slack = 4.0 * frame_error * half.sum()
        + 16.0 * f64::EPSILON * (c.abs().max() + extent.max() + translation.abs().max());
    let reach = extent.add_scalar(slack);
    Aabb {
        min: (c - reach).into(),
        max: (c + reach).into(),
    }
}

/// A random rotation and a translation at the origin, about 1, or about 1e6 away (by
/// `k % 3`): the poses the world-box tests of the volumes take, far ones whose rounding is
/// many times a volume's own ulps.
#[cfg(test)]
pub(crate) fn turned_far_pose(rng: &mut crate::generate::Rng, k: usize) -> Pose {
    let far = [0.0, 1.0, 1e6][k % 3];
    let t = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * far;
    Pose::new(rng.uniform_rotation(), t).unwrap_or_default()
}

/// Exact arithmetic on doubles for the tests that judge rounding: `a + b` as an
/// unevaluated sum of two doubles, exactly.
#[cfg(test)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let v = s - a;
    (s, (a - (s - v)) + (b - v))
}

/// `a · b` as an unevaluated sum of two doubles, exactly (see [`two_sum`]).
#[cfg(test)]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// A sum of doubles as a double-double, to about 2⁻¹⁰⁰ of its largest term (see
/// [`two_sum`]).
#[cfg(test)]
pub(crate) fn double_double_sum(terms: &[f64]) -> (f64, f64) {
    terms.iter().fold((0.0, 0.0), |(hi, lo), &t| {
        let (s, e) = two_sum(hi, t);
        two_sum(s, lo + e)
    })
}

/// The eight corners of the box `center + Σ ±half[i] · axes.row(i)`: for the tests of
/// volumes that must hold a whole box.
#[cfg(test)]
pub(crate) fn box_corners(
    center: &Vector3<f64>,
    axes: &Matrix3<f64>,
    half: &Vector3<f64>,
) -> [Vector3<f64>; 8] {
    std::array::from_fn(|corner| {
        let sign = |i: usize| if corner >> i & 1 == 1 { 1.0 } else { -1.0 };
        center
            + (0..3)
                .map(|i| axes.row(i).transpose() * half[i] * sign(i))
                .sum::<Vector3<f64>>()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::Rng;

    /// The header tags are the format's (formats/obbt.md) and the names the CLI's: fixed
    /// values, each read back to its kind, anything else refused.
    #[test]
    fn tags_and_names_are_fixed_and_read_back() {
        let bvs = [
            (BvKind::Obb, 1, "obb"),
            (BvKind::Aabb, 2, "aabb"),
            (BvKind::Sphere, 3, "sphere"),
        ];
        for (kind, tag, name) in bvs {
            assert_eq!((kind.tag(), kind.name()), (tag, name));
            assert_eq!(BvKind::from_tag(tag), Some(kind));
            assert_eq!(BvKind::from_name(name), Some(kind));
        }
        let layouts = [
            (Layout::Fast, 0, "fast", 1),
            (Layout::Compact, 1, "compact", 4),
        ];
        for (layout, tag, name, leaf_size) in layouts {
            assert_eq!((layout.tag(), layout.name()), (tag, name));
            assert_eq!(Layout::from_tag(tag), Some(layout));
            assert_eq!(Layout::from_name(name), Some(layout));
            assert_eq!(layout.default_leaf_size(), leaf_size);
        }
        for tag in [0, 4, 255] {
            assert_eq!(BvKind::from_tag(tag), None);
        }
        assert_eq!(Layout::from_tag(2), None);
        for name in ["", "OBB", "ball", "xyzzy"] {
            assert_eq!(BvKind::from_name(name), None);
            assert_eq!(Layout::from_name(name), None);
        }
    }

    /// A node's record fills exactly its stride, as the builder writes nodes back to back:
    /// the volume's bytes, the packed reference, zero padding, and nothing past the stride.
    #[test]
    fn node_records_fill_their_stride_and_no_more() {
        fn check<B: BoundingVolume>() {
            let positions = [[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [0.25, 2.0, 3.0]];
            let bv = B::enclose(&Matrix3::identity(), &positions, &[[0, 1, 2]]);
            let mut volume = vec![0u8; std::mem::size_of::<B>()];
            bv.write_le(&mut volume);
            let mut out = vec![0xAAu8; Node::<B>::SIZE + 16];
            Node::new(bv, 0x1234_5678).write_le(&mut out);
            let (record, past) = out.split_at(Node::<B>::SIZE);
            let (bytes, rest) = record.split_at(volume.len());
            let (packed, pad) = rest.split_at(4);
            assert_eq!(bytes, volume);
            assert_eq!(packed, 0x1234_5678u32.to_le_bytes());
            assert!(pad.iter().all(|&b| b == 0), "padding {pad:?}");
            assert!(
                past.iter().all(|&b| b == 0xAA),
                "written past the record: {past:?}"
            );
        }
        check::<Obb<f32>>();
        check::<Obb<f64>>();
        check::<Aabb<f64>>();
        check::<Sphere<f64>>();
        check::<CompactObb>();
    }

    /// Only f32 oriented boxes have a compact layout, and messages name the layout only
    /// when it is not the default.
    #[test]
    fn node_types_exist_only_as_stored() {
        for bv in BvKind::ALL {
            for precision in [Precision::F32, Precision::F64] {
                let compact = NodeType::new(bv, precision, Layout::Compact);
                assert_eq!(
                    compact.is_ok(),
                    (bv, precision) == (BvKind::Obb, Precision::F32)
                );
                let fast = NodeType::new(bv, precision, Layout::Fast).unwrap();
                assert_eq!(fast, NodeType::plain(bv, precision));
                assert_eq!(
                    (fast.bv(), fast.precision(), fast.layout()),
                    (bv, precision, Layout::Fast)
                );
            }
        }
        let compact = NodeType::new(BvKind::Obb, Precision::F32, Layout::Compact).unwrap();
        assert_eq!(compact.to_string(), "obb f32 compact");
        assert_eq!(
            NodeType::plain(BvKind::Sphere, Precision::F64).to_string(),
            "sphere f64"
        );
    }

    /// The broad phase trusts the world box to hold the whole posed box: every corner,
    /// mapped by the pose in f64, lies inside it, under turned frames and far translations
    /// whose rounding is many times the box's own ulps.
    #[test]
    fn posed_box_aabb_holds_every_posed_corner() {
        let mut rng = Rng::new(3);
        for k in 0..2000 {
            let pose = turned_far_pose(&mut rng, k);
            let axes = rng.uniform_rotation().transpose();
            let center = Vector3::new(rng.signed(), rng.signed(), rng.signed());
            let half = Vector3::new(rng.unit(), rng.unit(), rng.unit());
            let world = posed_box_aabb(&center, &axes, &half, 0.0, &pose);
            for (corner, local) in box_corners(&center, &axes, &half).iter().enumerate() {
                let p = pose.apply(local);
                for i in 0..3 {
                    assert!(
                        world.min[i] <= p[i] && p[i] <= world.max[i],
                        "pose {k}, corner {corner}: {p:?} outside {world:?}"
                    );
                }
            }
        }
    }
}
