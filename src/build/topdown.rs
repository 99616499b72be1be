//! Top-down construction: fit, enclose, split by centroid, repeat.
//!
//! Subtrees are built iteratively with an explicit stack (a mean split can be arbitrarily
//! unbalanced, so recursion depth is not bounded by log n). Nodes large enough to be worth
//! a task are split in parallel, and the subtrees are then laid out in the order a serial
//! build gives, so the output never depends on scheduling.

use super::{BuildOptions, SphereFit, SPLIT_AXIS_GAIN};
use crate::arr3::{self, dot};
use crate::bv::BoundingVolume;
use crate::fit::{principal_axes, principal_axes_and_vertices, FaceMoment, FaceMoments, FitMethod};
use crate::format::NodeRun;
use crate::stats::TreeShape;
use crate::tree::{Draft, NodeRef};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// The drafts of a whole tree (node 0 the root, children of a node adjacent and after it),
/// and the faces and their input ids permuted into leaf order.
pub(crate) struct DraftTree<B> {
    /// The node array as consecutive pieces (see [`Piece`]).
    pub pieces: Vec<Piece<B>>,
    /// Leaf statistics of the tree, gathered as it is built.
    pub shape: TreeShape,
    pub faces: Vec<[u32; 3]>,
    pub source_ids: Vec<u32>,
}

/// A run of consecutive nodes of the final array: `drafts[skip..]`, whose child indices
/// become final once `shift` is added. Subtrees built by different tasks are placed in
/// the array this way, without being copied.
#[derive(Debug)]
pub(crate) struct Piece<B> {
    drafts: Vec<Draft<B>>,
    skip: usize,
    shift: u32,
}

impl<B: Copy> Piece<B> {
    /// Sets the volume of every single-face leaf to that of its face: `volumes` by input
    /// face id, `source_ids` the input id of each leaf-ordered face.
    fn fill_leaves(&mut self, volumes: &[B], source_ids: &[u32]) {
        let skip = self.skip;
        for d in self.drafts.iter_mut().skip(skip) {
            if let NodeRef::Leaf { first, count: 1 } = d.refs {
                let id = source_ids.get(first as usize).copied();
                if let Some(&bv) = id.and_then(|id| volumes.get(id as usize)) {
                    d.bv = bv;
                }
            }
        }
    }

    /// The piece as the writer takes it: the nodes as built, and what to add to their child
    /// indices.
    pub fn run(&self) -> NodeRun<'_, B> {
        NodeRun {
            drafts: self.drafts.get(self.skip..).unwrap_or_default(),
            shift: self.shift,
        }
    }
}

/// Nodes with at least this many triangles have their halves built as separate tasks;
/// smaller subtrees are built by one thread. Small enough to leave a few dozen tasks on a
/// mesh like the bunny, so the cores run out of work together, and large enough that a
/// task's work dwarfs its overhead.
const PARALLEL_MIN_FACES: usize = 1024;
/// Deepest level split into tasks: bounds the recursion of `build_parallel`, which very
/// unbalanced splits could otherwise drive as deep as the tree.
const PARALLEL_MAX_DEPTH: u32 = 20;

/// A subtree as built: one task's drafts in local layout (root at 0), or a node split
/// into two tasks with the subtrees of its halves.
enum Subtree<B> {
    Serial(Vec<Draft<B>>, TreeShape),
    Split {
        bv: B,
        len: usize,
        shape: TreeShape,
        left: Box<Subtree<B>>,
        right: Box<Subtree<B>>,
    },
}

impl<B: Copy> Subtree<B> {
    fn len(&self) -> usize {
        match self {
            Subtree::Serial(drafts, _) => drafts.len(),
            Subtree::Split { len, .. } => *len,
        }
    }

    fn shape(&self) -> TreeShape {
        match self {
            Subtree::Serial(_, shape) | Subtree::Split { shape, .. } => *shape,
        }
    }

    /// Lays the subtree out as pieces. The layout is the one `build_serial` makes: a node
    /// is followed by its two children, then by the rest of the left subtree, then by the
    /// rest of the right one.
    fn place(self, pieces: &mut Vec<Piece<B>>) {
        self.place_root(0, pieces);
        self.place_rest(0, pieces);
    }

    /// Appends the root, for a subtree whose non-root nodes go at `base + local index`.
    fn place_root(&self, base: u32, pieces: &mut Vec<Piece<B>>) {
        let root = match self {
            Subtree::Serial(drafts, _) => match drafts.first() {
                Some(d) => d.shifted(base),
                None => return,
            },
            Subtree::Split { bv, .. } => Draft {
                bv: *bv,
                refs: NodeRef::Internal {
                    first: base + 1,
                    count: 2,
                },
            },
        };
        pieces.push(Piece {
            drafts: vec![root],
            skip: 0,
            shift: 0,
        });
    }

    /// Appends every node but the root (see [`Subtree::place_root`]).
    fn place_rest(self, base: u32, pieces: &mut Vec<Piece<B>>) {
        match self {
            Subtree::Serial(drafts, _) => {
                if drafts.len() > 1 {
                    pieces.push(Piece {
                        drafts,
                        skip: 1,
                        shift: base,
                    });
                }
            }
            Subtree::Split { left, right, .. } => {
                // Local layout: [root, left root, right root, left rest, right rest].
                let left_base = base + 2;
                let right_base = base + 1 + left.len() as u32;
                left.place_root(left_base, pieces);
                right.place_root(right_base, pieces);
                left.place_rest(left_base, pieces);
                right.place_rest(right_base, pieces);
            }
        }
    }
}

struct Context<'a> {
    positions: &'a [[f64; 3]],
    options: &'a BuildOptions,
    progress: Option<&'a AtomicU64>,
    /// Single-face leaves get their volumes later, from `leaf_volume` (a placeholder until
    /// then).
    defer_leaves: bool,
    /// The area moments of every input face, by input id, when some node is fitted to its
    /// triangles (empty otherwise).
    face_moments: &'a [FaceMoment],
}

pub(crate) fn build_drafts<B: BoundingVolume>(
    positions: &[[f64; 3]],
    input_faces: &[[u32; 3]],
    options: &BuildOptions,
    progress: Option<&AtomicU64>,
) -> DraftTree<B> {
    let mut faces = input_faces.to_vec();
    let mut source_ids: Vec<u32> = (0..faces.len() as u32).collect();
    // A single-face leaf's volume depends on its triangle alone, not on the tree. With
    // leaf size 1 every triangle becomes such a leaf, so their volumes are computed
    // apart, alongside the tree: that work keeps the second core busy while the first
    // is still fitting the root, which nothing else can start before.
    let defer_leaves = options.leaf_size == 1;
    // Nodes of one face take their frame from the triangle itself; larger ones may be
    // fitted to their triangles' moments, which are then worth computing once.
    let face_moments: Vec<FaceMoment> = if options.fit_for(2) == FitMethod::Triangles {
        input_faces
            .par_iter()
            .map(|f| FaceMoment::of(positions, f).unwrap_or_default())
            .collect()
    } else {
        Vec::new()
    };
    let ctx = Context {
        positions,
        options,
        progress,
        defer_leaves,
        face_moments: &face_moments,
    };
    let (tree, leaf_volumes) = if defer_leaves {
        let (tree, volumes) = rayon::join(
            || build_parallel::<B>(&ctx, &mut faces, &mut source_ids, 0, 0),
            || {
                input_faces
                    .par_iter()
                    .map(|f| leaf_volume::<B>(options, positions, f))
                    .collect::<Vec<B>>()
            },
        );
        (tree, Some(volumes))
    } else {
        let tree = build_parallel::<B>(&ctx, &mut faces, &mut source_ids, 0, 0);
        (tree, None)
    };
    let shape = tree.shape();
    let mut pieces = Vec::new();
    tree.place(&mut pieces);
    if let Some(volumes) = leaf_volumes {
        pieces
            .par_iter_mut()
            .for_each(|piece| piece.fill_leaves(&volumes, &source_ids));
    }
    DraftTree {
        pieces,
        shape,
        faces,
        source_ids,
    }
}

/// The volume of a leaf holding just `face`: exactly what the builder computes for such
/// a node.
fn leaf_volume<B: BoundingVolume>(
    options: &BuildOptions,
    positions: &[[f64; 3]],
    face: &[u32; 3],
) -> B {
    if let Some(ball) = minimal_ball::<B>(options, positions, face) {
        return ball;
    }
    let axes = principal_axes(options.fit_for(1), positions, std::slice::from_ref(face));
    B::enclose_vertices(&axes, positions, face)
}

/// The minimal-ball sphere of `vertices` when the build asks for one (sphere trees with
/// [`SphereFit::Minimal`]).
fn minimal_ball<B: BoundingVolume>(
    options: &BuildOptions,
    positions: &[[f64; 3]],
    vertices: &[u32],
) -> Option<B> {
    if options.sphere_fit == SphereFit::Minimal {
        B::enclose_vertices_minimal_ball(positions, vertices)
    } else {
        None
    }
}

/// Buffers reused from node to node by one task.
#[derive(Default)]
struct Scratch {
    /// The distinct vertices of the node.
    vertices: Vec<u32>,
    /// Centroid projections for the split.
    proj: Vec<f64>,
}

/// Fits node `faces` and, unless it is a leaf, partitions them (and `ids` alike) into two
/// non-empty halves, returning the size of the first.
fn fit_and_split<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    scratch: &mut Scratch,
) -> (B, Option<usize>) {
    if ctx.defer_leaves && faces.len() == 1 {
        if let Some(p) = ctx.progress {
            p.fetch_add(1, Ordering::Relaxed);
        }
        return (B::new_zeroed(), None);
    }
    let fit = ctx.options.fit_for(faces.len());
    let hull_points = ctx.options.hull_max_points as usize;
    let moments = if ctx.face_moments.is_empty() {
        FaceMoments::FromCorners
    } else {
        FaceMoments::Table {
            table: ctx.face_moments,
            ids,
        }
    };
    let axes = principal_axes_and_vertices(
        fit,
        hull_points,
        ctx.positions,
        faces,
        moments,
        &mut scratch.vertices,
    );
    let (axes, bv) = if ctx.options.model_axes {
        let [fitted, aligned] =
            B::enclose_vertices_fitted_and_aligned(&axes, ctx.positions, &scratch.vertices);
        // The fitted frame wins ties.
        if aligned.1.volume() < fitted.1.volume() {
            aligned
        } else {
            fitted
        }
    } else {
        (
            axes,
            B::enclose_vertices(&axes, ctx.positions, &scratch.vertices),
        )
    };
    let bv = minimal_ball(ctx.options, ctx.positions, &scratch.vertices).unwrap_or(bv);
    if faces.len() <= ctx.options.leaf_size as usize {
        if let Some(p) = ctx.progress {
            p.fetch_add(faces.len() as u64, Ordering::Relaxed);
        }
        return (bv, None);
    }
    // The first column: the axis of greatest spread, unless another splits much better.
    let columns: [[f64; 3]; 3] = axes.into();
    let [mut axis, _, _] = columns;
    if ctx.options.split_by_volume {
        axis = split_axis(ctx.positions, faces, &scratch.vertices, columns);
    }
    let proj = &mut scratch.proj;
    proj.clear();
    if ctx.face_moments.is_empty() {
        proj.extend(faces.iter().map(|f| {
            // Sum of the corners: the centroid times 3, which orders the same way.
            let mut s = 0.0;
            for &v in f {
                if let Some(p) = ctx.positions.get(v as usize) {
                    s += dot(axis, *p);
                }
            }
            s
        }));
    } else {
        // The centroids are at hand in the moments table.
        let centroid = |i: u32| ctx.face_moments.get(i as usize).map(FaceMoment::centroid);
        proj.extend(
            ids.iter()
                .map(|&i| centroid(i).map_or(0.0, |c| dot(axis, c))),
        );
    }
    (bv, Some(split(faces, ids, proj)))
}

/// The axis among `axes` (the node box's, the first of greatest spread) whose split through
/// the mean centroid leaves children of least total volume, measured along `axes`: the
/// first unless another's total is at most [`SPLIT_AXIS_GAIN`] of it. (Extents along the
/// node's axes rather than the children's own fits, which cost two fits per candidate and
/// chose no better on the benchmark meshes.) An axis that would leave a side empty is not
/// chosen.
fn split_axis(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    vertices: &[u32],
    axes: [[f64; 3]; 3],
) -> [f64; 3] {
    let attempt = PROJECTED.try_with(|cell| {
        cell.try_borrow_mut()
            .ok()
            .map(|mut buffer| split_axis_with(&mut buffer, positions, faces, vertices, axes))
    });
    match attempt {
        Ok(Some(axis)) => axis,
        // The thread is being torn down: a buffer of this call's own.
        _ => split_axis_with(&mut Vec::new(), positions, faces, vertices, axes),
    }
}

thread_local! {
    /// Per thread, each vertex's coordinates along a node's axes, indexed by vertex (sized
    /// by the mesh, so nothing is cleared between nodes: [`split_axis_with`] writes a
    /// node's vertices before its faces read them).
    static PROJECTED: std::cell::RefCell<Vec<[f64; 3]>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// [`split_axis`] with the buffer of vertex projections. `vertices` holds every corner of
/// `faces` (the node's distinct vertices), so each is projected once, not once per face
/// that uses it.
fn split_axis_with(
    projections: &mut Vec<[f64; 3]>,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    vertices: &[u32],
    axes: [[f64; 3]; 3],
) -> [f64; 3] {
    let [first, ..] = axes;
    // (Faces are checked against the positions before a build; a missing corner would
    // count as the origin.)
    let corner = |v: u32| positions.get(v as usize).copied().unwrap_or([0.0; 3]);
    // The mean centroid projected (times 3, as the corners' sums below): one pass of sums.
    let mut corners_sum = [0.0; 3];
    for &v in faces.iter().flatten() {
        let ([sx, sy, sz], [x, y, z]) = (corners_sum, corner(v));
        corners_sum = [sx + x, sy + y, sz + z];
    }
    let mean = arr3::map(axes, |axis| dot(axis, corners_sum) / faces.len() as f64);
    if projections.len() < positions.len() {
        projections.resize(positions.len(), [0.0; 3]);
    }
    for &v in vertices {
        if let Some(slot) = projections.get_mut(v as usize) {
            let p = corner(v);
            *slot = arr3::map(axes, |axis| dot(axis, p));
        }
    }
    let projected = |v: u32| projections.get(v as usize).copied().unwrap_or([0.0; 3]);
    // Per candidate axis, its two sides (below the mean, at or above it).
    let mut sides = [[SplitSide::EMPTY; 2]; 3];
    for face in faces {
        let [p, q, r] = arr3::map(*face, projected);
        // On each axis: the corners' sum (the centroid's, times 3), least and greatest.
        let along = arr3::map(arr3::zip(arr3::zip(p, q), r), |((x, y), z)| {
            (
                x + y + z,
                arr3::least(arr3::least(x, y), z),
                arr3::greatest(arr3::greatest(x, y), z),
            )
        });
        let [(_, lo0, hi0), (_, lo1, hi1), (_, lo2, hi2)] = along;
        let extents = [lo0, lo1, lo2, -hi0, -hi1, -hi2];
        for ([below, above], ((centroid, _, _), mean)) in
            sides.iter_mut().zip(arr3::zip(along, mean))
        {
            let side = if centroid >= mean { above } else { below };
            side.add(extents);
        }
    }
    let mut best = (f64::INFINITY, first);
    for (c, ([below, above], axis)) in arr3::zip(sides, axes).into_iter().enumerate() {
        if below.count == 0 || above.count == 0 {
            continue;
        }
        let total = below.volume() + above.volume();
        let merit = if c == 0 {
            total * SPLIT_AXIS_GAIN
        } else {
            total
        };
        if merit < best.0 {
            best = (merit, axis);
        }
    }
    best.1
}

/// One side of a candidate split in [`split_axis`]: the extents of its faces along the
/// node's axes, and how many there are.
#[derive(Clone, Copy)]
struct SplitSide {
    /// The least coordinate along each axis, then the greatest negated (so that both
    /// grow by taking the least).
    extents: [f64; 6],
    count: usize,
}

impl SplitSide {
    const EMPTY: SplitSide = SplitSide {
        extents: [f64::INFINITY; 6],
        count: 0,
    };

    /// Adds a face of `extents` (laid out as [`SplitSide::extents`]).
    #[inline(always)]
    fn add(&mut self, extents: [f64; 6]) {
        for (e, x) in self.extents.iter_mut().zip(extents) {
            *e = arr3::least(*e, x);
        }
        self.count += 1;
    }

    /// The volume of the extents.
    fn volume(&self) -> f64 {
        let [lo0, lo1, lo2, hi0, hi1, hi2] = self.extents;
        (-hi0 - lo0) * (-hi1 - lo1) * (-hi2 - lo2)
    }
}

/// Partitions by the centroid projections `proj` (one per face): below the mean to the
/// front. If that leaves one side empty (all centroids project alike), splits at the median
/// of the projections.
fn split(faces: &mut [[u32; 3]], ids: &mut [u32], proj: &mut [f64]) -> usize {
    let mean = proj.iter().sum::<f64>() / proj.len() as f64;
    let (mut i, mut j) = (0, proj.len());
    while i < j {
        // `i < j <= proj.len()`: the lookup always succeeds.
        if proj.get(i).is_some_and(|&x| x < mean) {
            i += 1;
        } else {
            j -= 1;
            proj.swap(i, j);
            faces.swap(i, j);
            ids.swap(i, j);
        }
    }
    if i == 0 || i == proj.len() {
        i = median_split(faces, ids, proj);
    }
    i
}

/// Orders by projection (ties by input id, so the result is fully determined) and splits in
/// the middle. Rare: only when every centroid falls on one side of the mean.
fn median_split(faces: &mut [[u32; 3]], ids: &mut [u32], proj: &[f64]) -> usize {
    let mid = faces.len() / 2;
    let mut order: Vec<usize> = (0..faces.len()).collect();
    // `order` holds indices of `faces`, `ids` and `proj` (all of one length): every lookup
    // succeeds, the fallbacks are never used.
    let key = |k: usize| {
        let p = proj.get(k).copied().unwrap_or(f64::NAN);
        (p, ids.get(k).copied().unwrap_or(u32::MAX))
    };
    order.select_nth_unstable_by(mid, |&a, &b| {
        let ((pa, ia), (pb, ib)) = (key(a), key(b));
        pa.total_cmp(&pb).then(ia.cmp(&ib))
    });
    let f: Vec<[u32; 3]> = order
        .iter()
        .filter_map(|&k| faces.get(k).copied())
        .collect();
    let d: Vec<u32> = order.iter().filter_map(|&k| ids.get(k).copied()).collect();
    if f.len() == faces.len() && d.len() == ids.len() {
        faces.copy_from_slice(&f);
        ids.copy_from_slice(&d);
    }
    mid
}

fn build_parallel<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    face_offset: u32,
    depth: u32,
) -> Subtree<B> {
    if depth >= PARALLEL_MAX_DEPTH || faces.len() < PARALLEL_MIN_FACES {
        let (drafts, shape) = build_serial(ctx, faces, ids, face_offset);
        return Subtree::Serial(drafts, shape);
    }
    let mut scratch = Scratch::default();
    let (bv, split) = fit_and_split::<B>(ctx, faces, ids, &mut scratch);
    let Some(mid) = split else {
        let mut shape = TreeShape::default();
        shape.leaf(1, faces.len() as u32);
        let leaf = Draft {
            bv,
            refs: NodeRef::Leaf {
                first: face_offset,
                count: faces.len() as u32,
            },
        };
        return Subtree::Serial(vec![leaf], shape);
    };
    let (fl, fr) = faces.split_at_mut(mid);
    let (il, ir) = ids.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_parallel::<B>(ctx, fl, il, face_offset, depth + 1),
        || build_parallel::<B>(ctx, fr, ir, face_offset + mid as u32, depth + 1),
    );
    Subtree::Split {
        bv,
        len: 1 + left.len() + right.len(),
        shape: TreeShape::parent(left.shape(), right.shape()),
        left: Box::new(left),
        right: Box::new(right),
    }
}

/// Builds one subtree with an explicit stack, depth first, children allocated as adjacent
/// pairs right after their parent's siblings: node indices always grow from parent to child.
fn build_serial<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    face_offset: u32,
) -> (Vec<Draft<B>>, TreeShape) {
    let placeholder = Draft {
        bv: B::new_zeroed(),
        refs: NodeRef::Leaf { first: 0, count: 0 },
    };
    let mut nodes = vec![placeholder];
    let mut shape = TreeShape::default();
    // (node, faces start, faces end, depth)
    let mut stack = vec![(0usize, 0usize, faces.len(), 1u32)];
    let mut scratch = Scratch::default();
    while let Some((slot, start, end, depth)) = stack.pop() {
        // Ranges and slots come from this loop's own splits, so they are always in bounds;
        // a miss would leave a placeholder node, which the encoder refuses (count 0).
        let (Some(node_faces), Some(node_ids)) =
            (faces.get_mut(start..end), ids.get_mut(start..end))
        else {
            continue;
        };
        let (bv, split) = fit_and_split::<B>(ctx, node_faces, node_ids, &mut scratch);
        let refs = match split {
            None => {
                shape.leaf(depth, (end - start) as u32);
                NodeRef::Leaf {
                    first: face_offset + start as u32,
                    count: (end - start) as u32,
                }
            }
            Some(mid) => {
                let first = nodes.len();
                nodes.push(placeholder);
                nodes.push(placeholder);
                // Right pushed first so the left subtree is laid out first.
                stack.push((first + 1, start + mid, end, depth + 1));
                stack.push((first, start, start + mid, depth + 1));
                NodeRef::Internal {
                    first: first as u32,
                    count: 2,
                }
            }
        };
        if let Some(node) = nodes.get_mut(slot) {
            *node = Draft { bv, refs };
        }
    }
    (nodes, shape)
}
