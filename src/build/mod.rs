//! The offline builder: a validated mesh in, a finished `.obbt` image out.
//!
//! Top-down (dissertation §3.1.1, §7.5.2): fit a frame to a node's triangles, enclose them,
//! split them by centroid with the plane orthogonal to one of the frame's axes (that of
//! greatest spread, or another whose halves are much smaller: [`BuildOptions::split_by_volume`])
//! through the mean centroid (the median if one side would be empty), and recurse until a
//! node holds at most `leaf_size` triangles. The split rule ignores the volume type, so OBB,
//! AABB and sphere trees of one mesh have the same shape and compare on equal footing.

mod rounding;
mod topdown;

pub use rounding::{rounding_loss, RoundingLoss, REPORTED_ROUNDING};

use crate::bv::{dispatch, BoundingVolume, BvKind, Layout, LayoutError, NodeType, VolumeVisitor};
use crate::fit::FitMethod;
use crate::format::{self, ObbtFile, TreeImage, WriteError};
use crate::mesh::TriMesh;
use crate::placement::Placement;
use crate::real::{Precision, Real};
use crate::stats::{TreeShape, TreeStats};
use crate::tree::{EncodeError, BINARY_MAX_FACE, VARIABLE_MAX_LEAF_FACES};
use std::borrow::Cow;
use std::sync::atomic::AtomicU64;

/// Everything that decides the shape and contents of a built tree. The same mesh and options
/// always give a byte-identical file, whatever the number of threads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// The bounding volume stored in every node.
    pub bv: BvKind,
    /// The stored precision of vertices and volumes.
    pub precision: Precision,
    /// How the nodes are laid out: [`Layout::Compact`] (f32 boxes only) stores quantised
    /// boxes for smaller files and slower queries; pair it with
    /// [`Layout::default_leaf_size`] unless you choose a leaf size.
    pub layout: Layout,
    /// The covariance the node frames are fitted to.
    pub fit: FitMethod,
    /// With [`FitMethod::Hull`], the fewest faces a node needs for its frame to be fitted to
    /// its convex hull; nodes with fewer are fitted to their triangles
    /// ([`FitMethod::Triangles`]). At least 1; default [`DEFAULT_HULL_MIN_FACES`]; 1 fits
    /// every node to its hull (with [`BuildOptions::hull_max_points`] at `u32::MAX` and
    /// [`BuildOptions::model_axes`] and [`BuildOptions::split_by_volume`] off too, exactly
    /// as §3.4 describes). Ignored by the other methods.
    pub hull_min_faces: u32,
    /// With [`FitMethod::Hull`], the most vertices a node's hull is computed over: a node
    /// with more has its hull taken over an evenly spaced sample of this many of them and
    /// the six that reach its bounding box (its box extents are still taken over every
    /// vertex, so this only shapes the frame; the sample also stands for the node's points
    /// where the fit breaks ties between equal eigenvalues). At least 4, the fewest points
    /// of a solid hull; default [`DEFAULT_HULL_MAX_POINTS`]; `u32::MAX` takes every hull
    /// over every vertex.
    pub hull_max_points: u32,
    /// Also fit each node's volume to the model's own axes and keep that one wherever its
    /// volume is smaller than the fitted frame's (default on). Parts modelled along their
    /// axes (CAD) have many nodes whose covariance frame is tilted against their flat sides;
    /// on them the model's axes make far fewer node pairs and box tests, for a little more
    /// build time (the figures are in docs/results). Off (with
    /// [`BuildOptions::hull_min_faces`] 1, [`BuildOptions::hull_max_points`] `u32::MAX`
    /// and [`BuildOptions::split_by_volume`] off) gives §3.4 exactly.
    pub model_axes: bool,
    /// Split each node along whichever of its box's three axes divides it into the least
    /// total volume, measured along those axes; the first axis (greatest spread) unless
    /// another leaves at most [`SPLIT_AXIS_GAIN`] of its total (default on). A CAD part's
    /// long, thin triangles spread a node most along a direction its halves still share, so
    /// that splitting across it leaves two boxes nearly as large as their parent; on such
    /// parts the chosen axis makes a quarter to a half of the box and triangle tests, and
    /// on the other benchmark meshes about as many (the figures are in docs/results), for
    /// about a third more one-thread build time on small parts (a tenth on the bunny). Off
    /// always splits along the first axis, as §3.4 does.
    pub split_by_volume: bool,
    /// Where sphere volumes are centred (sphere trees only; ignored by the others).
    pub sphere_fit: SphereFit,
    /// Largest number of triangles in a leaf, 1 to 128. With 1 the tree is binary with
    /// single-face leaves and uses the compact binary encoding.
    pub leaf_size: u32,
    /// Stored units per input unit: every input coordinate is multiplied by it before it is
    /// stored (0.001 turns a mesh in millimetres into one in metres). Finite and greater than
    /// 0; default 1. See [`Placement`].
    pub scale: f64,
    /// Move the centre of the (scaled) mesh's bounding box to the origin: the offset
    /// `−scale · centre` is added to every vertex and recorded in the file. Default off.
    pub center: bool,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            bv: BvKind::Obb,
            precision: Precision::F32,
            layout: Layout::Fast,
            fit: FitMethod::Hull,
            hull_min_faces: DEFAULT_HULL_MIN_FACES,
            hull_max_points: DEFAULT_HULL_MAX_POINTS,
            leaf_size: 1,
            model_axes: true,
            split_by_volume: true,
            sphere_fit: SphereFit::default(),
            scale: 1.0,
            center: false,
        }
    }
}

/// Where a sphere tree centres each node's sphere.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SphereFit {
    /// At the centre of the node's box along its fitted frame (the default: for elongated
    /// nodes far tighter than the centroid, and nearly free to compute).
    #[default]
    BoxCentre,
    /// At the centre of the smallest ball containing the node's vertices (Welzl's
    /// algorithm): the tightest sphere, for a build that costs more. The dissertation's sphere trees are compared with these.
    Minimal,
}

/// With [`BuildOptions::split_by_volume`], the share of the first axis's total child volume
/// another axis must leave at most to be split along instead: a clear gain, so that nodes
/// where the axes differ little keep the first (on organic meshes, where the choice gained
/// nothing, most do).
pub const SPLIT_AXIS_GAIN: f64 = 0.8;

/// The default [`BuildOptions::hull_min_faces`]. The hull fit earns its cost on large nodes,
/// whose triangles sample the shape unevenly or hide detail inside it (§3.4); on a small
/// patch of surface its hull adds phantom faces across every concavity, and the triangles'
/// own covariance gives boxes as tight or tighter. Below this size the triangles' frame made
/// fewer box tests and faster builds on every benchmark mesh; a larger threshold built
/// faster still but slowed distance queries (the figures are in docs/results).
pub const DEFAULT_HULL_MIN_FACES: u32 = 512;

/// The default [`BuildOptions::hull_max_points`]. The top levels of a tree hold most of the
/// remaining hull work, all the more on convex shapes, whose every vertex is a hull vertex;
/// the hull of an evenly spaced sample of a dense surface has nearly the same covariance.
/// Against larger samples, this one took fewer build instructions on each benchmark mesh
/// measured (`examples/profile_build`) and left the box tests and node pairs of collision
/// and distance queries within a few percent either way (`examples/tree_work`); the
/// figures are in docs/results.
pub const DEFAULT_HULL_MAX_POINTS: u32 = 512;

/// The least [`BuildOptions::hull_max_points`]: a solid hull needs four points.
pub const MIN_HULL_POINTS: u32 = 4;

impl BuildOptions {
    /// A [`BuildOptions::hull_max_points`] as written on a command line: a count, or `all`
    /// for every vertex (`u32::MAX`). `None` for anything else; the count's range is
    /// [`BuildOptions::validate`]'s to check.
    pub fn parse_hull_max_points(text: &str) -> Option<u32> {
        match text {
            "all" => Some(u32::MAX),
            count => count.parse().ok(),
        }
    }

    /// The fit of a node of `faces` faces: [`BuildOptions::fit`], except that a
    /// [`FitMethod::Hull`] build fits nodes below [`BuildOptions::hull_min_faces`] to their
    /// triangles.
    pub fn fit_for(&self, faces: usize) -> FitMethod {
        if self.fit == FitMethod::Hull && faces < self.hull_min_faces as usize {
            FitMethod::Triangles
        } else {
            self.fit
        }
    }

    /// The checks of the options alone, before any mesh is read: `leaf_size` in 1..=128,
    /// `hull_min_faces` at least 1, `hull_max_points` at least 4, a finite `scale`
    /// greater than 0, and minimal spheres only for sphere trees. [`build`] runs them too.
    ///
    /// # Errors
    ///
    /// The first check that fails: [`BuildError::LeafSize`], [`BuildError::HullMinFaces`],
    /// [`BuildError::HullMaxPoints`], [`BuildError::Scale`] or [`BuildError::SphereFit`].
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::build::{BuildError, BuildOptions};
    ///
    /// assert!(BuildOptions::default().validate().is_ok());
    /// let options = BuildOptions { leaf_size: 0, ..Default::default() };
    /// assert!(matches!(options.validate(), Err(BuildError::LeafSize(0))));
    /// ```
    pub fn validate(&self) -> Result<(), BuildError> {
        if !(1..=VARIABLE_MAX_LEAF_FACES).contains(&self.leaf_size) {
            return Err(BuildError::LeafSize(self.leaf_size));
        }
        if self.hull_min_faces < 1 {
            return Err(BuildError::HullMinFaces(self.hull_min_faces));
        }
        if self.hull_max_points < MIN_HULL_POINTS {
            return Err(BuildError::HullMaxPoints(self.hull_max_points));
        }
        if !Placement::is_valid_scale(self.scale) {
            return Err(BuildError::Scale(self.scale));
        }
        if self.sphere_fit == SphereFit::Minimal && self.bv != BvKind::Sphere {
            return Err(BuildError::SphereFit(self.bv));
        }
        self.node_type()?;
        Ok(())
    }

    /// The node type the options ask for.
    ///
    /// # Errors
    ///
    /// [`BuildError::Layout`] for a layout the volume and precision do not have.
    pub fn node_type(&self) -> Result<NodeType, BuildError> {
        Ok(NodeType::new(self.bv, self.precision, self.layout)?)
    }
}

/// Why a tree could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// `leaf_size` outside 1..=128.
    #[error("leaf size {0} is out of range (1 to {VARIABLE_MAX_LEAF_FACES})")]
    LeafSize(u32),
    /// `hull_min_faces` is 0.
    #[error("hull min faces {0} is out of range (at least 1; --hull-min-faces)")]
    HullMinFaces(u32),
    /// `hull_max_points` is below [`MIN_HULL_POINTS`].
    #[error("hull max points {0} is out of range (at least {MIN_HULL_POINTS}, or all; --hull-max-points)")]
    HullMaxPoints(u32),
    /// `scale` is not a finite number greater than 0.
    #[error("scale {0} is not a finite number greater than 0 (--scale)")]
    Scale(f64),
    /// A stored coordinate beyond what the compact layout's boxes can span.
    #[error("vertex {vertex}: coordinate {value:e} is beyond the compact layout's range (±{:e}; its half-widths stop at 3.4e38): use --layout fast, or --scale", crate::bv::COMPACT_COORDINATE_LIMIT)]
    CompactRange {
        /// The vertex (0-based input order).
        vertex: usize,
        /// Its stored coordinate.
        value: f64,
    },
    /// The compact layout asked for a tree other than f32 oriented boxes.
    #[error(transparent)]
    Layout(#[from] LayoutError),
    /// Minimal spheres asked for a tree of another volume type.
    #[error("--sphere-fit minimal applies to sphere trees, not to {} trees (--bv sphere)", .0.name())]
    SphereFit(BvKind),
    /// The mesh is too large for the 32-bit references of the file format.
    // The reason is in the message, not in `source()`: callers that keep only the message
    // (a scene's error lines) show it, and a chain printer would otherwise show it twice.
    #[error("the mesh is too large for the .obbt format: {0}")]
    TooLarge(EncodeError),
    /// More triangles or vertices than a 32-bit count holds.
    #[error("the mesh has {count} {what}; the .obbt format holds at most {max}")]
    TooManyElements {
        /// "triangles" or "vertices".
        what: &'static str,
        /// The count found.
        count: usize,
        /// The largest count the format holds.
        max: u64,
    },
    /// The `.obbt` image could not be laid out in memory: it is larger than this platform
    /// can address (32-bit hosts), or (a bug) the header written fails the reader's checks.
    #[error("cannot lay out the .obbt image: {0}")]
    Image(String),
    /// A placed coordinate is too large for the stored precision (beyond about 3.4e38 in
    /// f32).
    #[error("vertex {vertex} coordinate {value:e} does not fit the stored {precision} precision (it rounds to infinity); build with --precision f64")]
    CoordinateOverflow {
        /// Index of the vertex (0-based, input order).
        vertex: usize,
        /// The coordinate to be stored: the input coordinate after the placement.
        value: f64,
        /// `f32` or `f64`.
        precision: &'static str,
    },
    /// Scaling or centring takes a coordinate beyond the f64 range.
    #[error("vertex {vertex} coordinate {value:e} is beyond the f64 range after the placement ({placement}); use a smaller --scale")]
    PlacementOverflow {
        /// Index of the vertex (0-based, input order).
        vertex: usize,
        /// The input coordinate.
        value: f64,
        /// The placement that was applied.
        placement: Placement,
    },
}

/// Builds the tree of `mesh` and lays it out as a complete `.obbt` image in memory (the same
/// bytes [`ObbtFile::write_atomic`] puts on disk).
///
/// The vertices are first placed as `options` asks ([`Placement::for_points`]: `scale`, and
/// with `center` the bounding-box centre moved to the origin), in f64; the tree, the stored
/// vertices and the header's bounds are all in that stored frame, and a placement other than
/// the identity is recorded in the file.
///
/// `progress`, when given, is advanced by the number of triangles placed in leaves, up to
/// `mesh.faces().len()`; another thread may poll it.
///
/// # Errors
///
/// - Any error of [`BuildOptions::validate`] for the options alone.
/// - [`BuildError::PlacementOverflow`] if scaling or centring takes a coordinate beyond
///   the f64 range; [`BuildError::CoordinateOverflow`] if a placed coordinate rounds to
///   infinity in the stored precision (f32).
/// - [`BuildError::TooManyElements`] / [`BuildError::TooLarge`] if the mesh or its tree
///   does not fit the format's 32-bit counts and references.
/// - [`BuildError::Image`] if the image is larger than this platform can address.
///
/// # Examples
///
/// ```
/// use obbtree::build::{build, BuildOptions};
/// use obbtree::format::ObbtFile;
/// use obbtree::mesh::TriMesh;
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let cow = TriMesh::load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref())?;
/// let tree = build(&cow, &BuildOptions::default(), None)?;
/// tree.verify()?;
/// assert_eq!(tree.info().triangles as usize, cow.faces().len());
///
/// // On disk, and back.
/// let path = std::env::temp_dir().join(format!("obbtree-doc-build-{}.obbt", std::process::id()));
/// tree.write_atomic(&path)?;
/// let opened = ObbtFile::open(&path)?;
/// assert_eq!(opened.info().triangles, tree.info().triangles);
/// drop(opened);
/// std::fs::remove_file(&path)?;
/// # Ok(())
/// # }
/// ```
pub fn build(
    mesh: &TriMesh,
    options: &BuildOptions,
    progress: Option<&AtomicU64>,
) -> Result<ObbtFile, BuildError> {
    options.validate()?;
    /// [`build_as`] with the volume type the options name.
    struct Build<'a> {
        mesh: &'a TriMesh,
        options: &'a BuildOptions,
        progress: Option<&'a AtomicU64>,
    }
    impl VolumeVisitor for Build<'_> {
        type Output = Result<ObbtFile, BuildError>;
        fn visit<B: BoundingVolume>(self) -> Self::Output {
            build_as::<B>(self.mesh, self.options, self.progress)
        }
    }
    let visitor = Build {
        mesh,
        options,
        progress,
    };
    dispatch(options.node_type()?, visitor)
}

fn build_as<B: BoundingVolume>(
    mesh: &TriMesh,
    options: &BuildOptions,
    progress: Option<&AtomicU64>,
) -> Result<ObbtFile, BuildError> {
    // Face indices must fit a binary leaf (a non-negative i32); vertex ids a u32.
    let limits = [
        (
            "triangles",
            mesh.faces().len(),
            u64::from(BINARY_MAX_FACE) + 1,
        ),
        ("vertices", mesh.vertices().len(), u64::from(u32::MAX)),
    ];
    for (what, count, max) in limits {
        if count as u64 > max {
            return Err(BuildError::TooManyElements { what, count, max });
        }
    }
    let placement = Placement::for_points(options.scale, options.center, mesh.vertices());
    // The identity is not applied at all: `1 · x + 0` would turn a −0 into +0, and files
    // built without a placement stay byte-identical to those of format 1.0.
    let placed: Cow<'_, [[f64; 3]]> = if placement.is_identity() {
        Cow::Borrowed(mesh.vertices())
    } else {
        Cow::Owned(
            mesh.vertices()
                .iter()
                .map(|&p| placement.apply(p))
                .collect(),
        )
    };
    // Everything downstream sees the vertices exactly as stored, so the volumes contain the
    // stored (possibly f32-rounded) triangles, not the input ones.
    let stored: Vec<[B::Real; 3]> = placed
        .iter()
        .map(|p| p.map(<B::Real as Real>::from_f64_nearest))
        .collect();
    let positions: Vec<[f64; 3]> = stored.iter().map(crate::real::point_to_f64).collect();
    // Input coordinates are finite (TriMesh checks), but a placement can take them beyond
    // the f64 range, and f32 rounds beyond 3.4e38 to infinity: either would give a file that
    // its own verify refuses.
    let overflow = positions.iter().zip(placed.iter()).zip(mesh.vertices());
    for (vertex, ((p, placed), input)) in overflow.enumerate() {
        let Some(k) = p.iter().position(|c| !c.is_finite()) else {
            continue;
        };
        let coordinate = |point: &[f64; 3]| point.get(k).copied().unwrap_or(f64::INFINITY);
        return Err(if coordinate(placed).is_finite() {
            BuildError::CoordinateOverflow {
                vertex,
                value: coordinate(placed),
                precision: <B::Real as Real>::PRECISION.name(),
            }
        } else {
            BuildError::PlacementOverflow {
                vertex,
                value: coordinate(input),
                placement,
            }
        });
    }
    // Compact boxes store half-widths as bfloat16, finite up to 3.4e38: a model within
    // ±COMPACT_COORDINATE_LIMIT has boxes at most √3 times that wide.
    if B::NODE_LAYOUT == Layout::Compact {
        let limit = crate::bv::COMPACT_COORDINATE_LIMIT;
        let beyond = positions.iter().enumerate().find_map(|(vertex, p)| {
            p.iter()
                .find(|c| c.abs() > limit)
                .map(|&value| (vertex, value))
        });
        if let Some((vertex, value)) = beyond {
            return Err(BuildError::CompactRange { vertex, value });
        }
    }
    // The statistics that do not depend on the tree are found alongside it.
    let (draft, stats) = rayon::join(
        || topdown::build_drafts::<B>(&positions, mesh.faces(), options, progress),
        || TreeStats::new(TreeShape::default(), &positions, mesh.faces()),
    );
    let stats = TreeStats {
        shape: draft.shape,
        ..stats
    };
    let image = TreeImage {
        vertices: &stored,
        faces: &draft.faces,
        source_ids: &draft.source_ids,
        nodes: draft.pieces.iter().map(topdown::Piece::run).collect(),
        fit: options.fit,
        // `validate` checked it against 128.
        leaf_size: u16::try_from(options.leaf_size)
            .map_err(|_| BuildError::LeafSize(options.leaf_size))?,
        stats,
        placement,
    };
    Ok(format::serialize(&image)?)
}

impl From<WriteError> for BuildError {
    fn from(e: WriteError) -> BuildError {
        match e {
            WriteError::Encode(e) => BuildError::TooLarge(e),
            WriteError::Image(problem) => BuildError::Image(problem),
        }
    }
}
