//! Top-down construction: fit, enclose, split by centroid, repeat.
//!
//! Subtrees are built iteratively with an explicit stack (a mean split can be arbitrarily
//! unbalanced, so recursion depth is not bounded by log n). Only the top few levels run in
//! parallel, and their results are merged in a fixed order, so the output never depends on
//! scheduling.

use super::BuildOptions;
use crate::bv::BoundingVolume;
use crate::fit::principal_axes;
use crate::tree::NodeRef;
use std::sync::atomic::{AtomicU64, Ordering};

/// A node during construction: indices are local to the subtree being built until merged.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draft<B> {
    pub bv: B,
    pub refs: NodeRef,
}

/// The drafts of a whole tree (node 0 the root, children of a node adjacent and after it),
/// and the faces and their input ids permuted into leaf order.
pub(crate) struct DraftTree<B> {
    pub nodes: Vec<Draft<B>>,
    pub faces: Vec<[u32; 3]>,
    pub source_ids: Vec<u32>,
}

/// Levels split in parallel before each subtree is built by one thread: 2^3 = 8 tasks keep
/// two cores busy without paying for many merges.
const PARALLEL_LEVELS: u32 = 3;
/// Below this many triangles a subtree is built by one thread: splitting cost would dominate.
const PARALLEL_MIN_FACES: usize = 4096;

struct Context<'a> {
    positions: &'a [[f64; 3]],
    options: &'a BuildOptions,
    progress: Option<&'a AtomicU64>,
}

pub(crate) fn build_drafts<B: BoundingVolume>(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    options: &BuildOptions,
    progress: Option<&AtomicU64>,
) -> DraftTree<B> {
    let mut faces = faces.to_vec();
    let mut source_ids: Vec<u32> = (0..faces.len() as u32).collect();
    let ctx = Context {
        positions,
        options,
        progress,
    };
    let nodes = build_parallel(&ctx, &mut faces, &mut source_ids, 0, PARALLEL_LEVELS);
    DraftTree {
        nodes,
        faces,
        source_ids,
    }
}

/// Fits node `faces` and, unless it is a leaf, partitions them (and `ids` alike) into two
/// non-empty halves, returning the size of the first.
fn fit_and_split<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    scratch: &mut Vec<f64>,
) -> (B, Option<usize>) {
    let axes = principal_axes(ctx.options.fit, ctx.positions, faces);
    let bv = B::enclose(&axes, ctx.positions, faces);
    if faces.len() <= ctx.options.leaf_size as usize {
        if let Some(p) = ctx.progress {
            p.fetch_add(faces.len() as u64, Ordering::Relaxed);
        }
        return (bv, None);
    }
    let axis = [axes[(0, 0)], axes[(1, 0)], axes[(2, 0)]];
    (bv, Some(split(ctx.positions, axis, faces, ids, scratch)))
}

/// Partitions by centroid projection on `axis`: below the mean to the front. If that leaves
/// one side empty (all centroids project alike), splits at the median of the projections.
fn split(
    positions: &[[f64; 3]],
    axis: [f64; 3],
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    proj: &mut Vec<f64>,
) -> usize {
    proj.clear();
    proj.extend(faces.iter().map(|f| {
        // Sum of the corners: the centroid times 3, which orders the same way.
        let mut s = 0.0;
        for &v in f {
            if let Some(p) = positions.get(v as usize) {
                s += axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
            }
        }
        s
    }));
    let mean = proj.iter().sum::<f64>() / proj.len() as f64;
    let (mut i, mut j) = (0, proj.len());
    while i < j {
        if proj[i] < mean {
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
    order.select_nth_unstable_by(mid, |&a, &b| {
        proj[a].total_cmp(&proj[b]).then(ids[a].cmp(&ids[b]))
    });
    let f: Vec<[u32; 3]> = order.iter().map(|&k| faces[k]).collect();
    let d: Vec<u32> = order.iter().map(|&k| ids[k]).collect();
    faces.copy_from_slice(&f);
    ids.copy_from_slice(&d);
    mid
}

fn build_parallel<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    face_offset: u32,
    levels: u32,
) -> Vec<Draft<B>> {
    if levels == 0 || faces.len() < PARALLEL_MIN_FACES {
        return build_serial(ctx, faces, ids, face_offset);
    }
    let mut scratch = Vec::new();
    let (bv, split) = fit_and_split::<B>(ctx, faces, ids, &mut scratch);
    let Some(mid) = split else {
        return vec![Draft {
            bv,
            refs: NodeRef::Leaf {
                first: face_offset,
                count: faces.len() as u32,
            },
        }];
    };
    let (fl, fr) = faces.split_at_mut(mid);
    let (il, ir) = ids.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_parallel::<B>(ctx, fl, il, face_offset, levels - 1),
        || build_parallel::<B>(ctx, fr, ir, face_offset + mid as u32, levels - 1),
    );
    merge(bv, left, right)
}

/// One parent over two subtrees in local layout `[root, children..., rest]`: the result is
/// `[parent, left root, right root, left rest, right rest]`, re-indexed.
fn merge<B: BoundingVolume>(bv: B, left: Vec<Draft<B>>, right: Vec<Draft<B>>) -> Vec<Draft<B>> {
    let shift = |d: Draft<B>, by: u32| match d.refs {
        NodeRef::Internal { first, count } => Draft {
            bv: d.bv,
            refs: NodeRef::Internal {
                first: first + by,
                count,
            },
        },
        leaf => Draft {
            bv: d.bv,
            refs: leaf,
        },
    };
    let nl = left.len() as u32;
    // The roots move to 1 and 2, left node j >= 1 to j + 2, right node j >= 1 to j + nl + 1.
    // A local child index is never 0, so shifting every internal reference is exact.
    let mut out = Vec::with_capacity(1 + left.len() + right.len());
    out.push(Draft {
        bv,
        refs: NodeRef::Internal { first: 1, count: 2 },
    });
    let mut l = left.into_iter();
    let mut r = right.into_iter();
    out.extend(l.next().map(|d| shift(d, 2)));
    out.extend(r.next().map(|d| shift(d, nl + 1)));
    out.extend(l.map(|d| shift(d, 2)));
    out.extend(r.map(|d| shift(d, nl + 1)));
    out
}

/// Builds one subtree with an explicit stack, depth first, children allocated as adjacent
/// pairs right after their parent's siblings: node indices always grow from parent to child.
fn build_serial<B: BoundingVolume>(
    ctx: &Context,
    faces: &mut [[u32; 3]],
    ids: &mut [u32],
    face_offset: u32,
) -> Vec<Draft<B>> {
    let placeholder = Draft {
        bv: B::new_zeroed(),
        refs: NodeRef::Leaf { first: 0, count: 0 },
    };
    let mut nodes = vec![placeholder];
    let mut stack = vec![(0usize, 0usize, faces.len())];
    let mut scratch = Vec::new();
    while let Some((slot, start, end)) = stack.pop() {
        let (bv, split) = fit_and_split::<B>(
            ctx,
            &mut faces[start..end],
            &mut ids[start..end],
            &mut scratch,
        );
        let refs = match split {
            None => NodeRef::Leaf {
                first: face_offset + start as u32,
                count: (end - start) as u32,
            },
            Some(mid) => {
                let first = nodes.len();
                nodes.push(placeholder);
                nodes.push(placeholder);
                // Right pushed first so the left subtree is laid out first.
                stack.push((first + 1, start + mid, end));
                stack.push((first, start, start + mid));
                NodeRef::Internal {
                    first: first as u32,
                    count: 2,
                }
            }
        };
        nodes[slot] = Draft { bv, refs };
    }
    nodes
}
