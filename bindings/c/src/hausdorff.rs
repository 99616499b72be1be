//! The Hausdorff distance between two posed trees.

use super::{deref, guard, read_pose, slot, work, ObbtreeStatus, ObbtreeTree, ObbtreeWork};
use obbtree::query::{hausdorff, HausdorffDirection, HausdorffOptions};

/// The answer of `obbtree_hausdorff`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeHausdorffResult {
    /// The Hausdorff distance found (world units): the distance from the witness to the
    /// other model; the true distance is at least this.
    pub distance: f64,
    /// A proven bound the true distance does not exceed (rounding aside).
    pub upper_bound: f64,
    /// 0 when the witness is `point_a` (h(A, B)), 1 when it is `point_b` (h(B, A), only
    /// with `symmetric`).
    pub b_to_a: bool,
    /// The point on A, world frame.
    pub point_a: [f64; 3],
    /// The point on B, world frame.
    pub point_b: [f64; 3],
    /// Input-mesh id of A's triangle holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of B's triangle holding `point_b`.
    pub tri_b: u32,
    /// Work done.
    pub work: ObbtreeWork,
}

/// The Hausdorff distance from A at `pose_a` to B at `pose_b`: the largest distance from a
/// point of A's surface to B's, with that point (the witness) and its closest point on B;
/// with `symmetric`, the larger of that and the reverse. The answer `h` and the true `h*`
/// satisfy `h <= h* <= max(h (1 + rel_err), h + abs_err)`; with both 0, exact to f64
/// rounding wherever the bounds close, which they do not quite where B curves or where the
/// surfaces nearly coincide (`upper_bound` says how close). The trees may be of any volume
/// types and precisions. `OBBTREE_STATUS_BAD_ARGUMENT` for a negative or non-finite error,
/// or models posed farther than 1e150 from each other's frame origin
/// (`obbtree::query::MAX_COORDINATE`).
///
/// # Safety
///
/// `a`, `b` are NULL or open trees; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `out` is NULL or points at a writable result.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_hausdorff(
    a: *const ObbtreeTree,
    pose_a: *const f64,
    b: *const ObbtreeTree,
    pose_b: *const f64,
    rel_err: f64,
    abs_err: f64,
    symmetric: bool,
    out: *mut ObbtreeHausdorffResult,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: forwarded from the caller's contract.
        let (out, a, b, pa, pb) = unsafe {
            (
                slot(out, "out")?,
                deref(a, "a")?,
                deref(b, "b")?,
                read_pose(pose_a, "pose_a")?,
                read_pose(pose_b, "pose_b")?,
            )
        };
        let options = HausdorffOptions {
            rel_err,
            abs_err,
            symmetric,
            warm_start: None,
        };
        let h = hausdorff(&a.file, &pa, &b.file, &pb, &options)?;
        out.write(ObbtreeHausdorffResult {
            distance: h.distance,
            upper_bound: h.upper_bound,
            b_to_a: h.direction == HausdorffDirection::BToA,
            point_a: h.point_a,
            point_b: h.point_b,
            tri_a: h.tri_a,
            tri_b: h.tri_b,
            work: work(&h.work),
        });
        Ok(())
    })
}
