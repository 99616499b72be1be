//! Contact geometry: where the contacting triangle pairs of two posed trees meet.

use super::{read_pose, slot, slots, with_pair, Error, ObbtreePair, ObbtreeStatus};
use obbtree::query::triangle::IntersectionKind;
use obbtree::query::CollideOptions;

/// Where one contacting triangle pair meets, world frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeContact {
    /// Input-mesh id of A's triangle.
    pub tri_a: u32,
    /// Input-mesh id of B's triangle.
    pub tri_b: u32,
    /// 0: the triangles cross and `points` holds the two ends of the segment they share
    /// (equal when they touch at a point); 1: they are coplanar and `points` holds the
    /// corners of the polygon they share, in order.
    pub coplanar: bool,
    /// How many of `points` are used (1 to 6).
    pub point_count: u32,
    /// The segment's ends or the polygon's corners; the unused ones are NaN.
    pub points: [[f64; 3]; 6],
    /// The largest distance from one of `points` to either triangle, as computed.
    pub residual: f64,
}

/// Every contacting triangle pair of A at `pose_a` and B at `pose_b` with where it meets,
/// sorted by (A, B) id. The contacts go to `contacts`, which holds `capacity` of them
/// (NULL and 0 for the totals only); `*count` gets the number of pairs, `*curve_length`
/// the summed length of the crossing pairs' segments and `*overlap_area` the summed area
/// of the polygons coplanar pairs share (each out pointer may be NULL). When `contacts` is
/// too short the call returns `OBBTREE_STATUS_BUFFER_TOO_SMALL` with the totals complete
/// and the first `capacity` contacts written.
///
/// # Safety
///
/// `pair` is NULL or a live handle; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `contacts` is NULL or points at `capacity` writable contacts; `count`,
/// `curve_length`, `overlap_area` are NULL or writable. Outputs do not overlap.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_pair_contact_geometry(
    pair: *mut ObbtreePair,
    pose_a: *const f64,
    pose_b: *const f64,
    contacts: *mut ObbtreeContact,
    capacity: usize,
    count: *mut usize,
    curve_length: *mut f64,
    overlap_area: *mut f64,
) -> ObbtreeStatus {
    super::guard(|| {
        let totals_only = contacts.is_null() && capacity == 0;
        // SAFETY: forwarded from the caller's contract.
        let (pa, pb, out) = unsafe {
            (
                read_pose(pose_a, "pose_a")?,
                read_pose(pose_b, "pose_b")?,
                if totals_only {
                    &mut []
                } else {
                    slots(contacts, capacity, "contacts")?
                },
            )
        };
        let options = CollideOptions {
            geometry: true,
            ..CollideOptions::default()
        };
        let query = |state: &mut super::PairState| -> Result<_, Error> {
            let super::PairState { query, collide } = state;
            query.collide_into(&pa, &pb, &options, collide)?;
            for (slot, c) in out.iter_mut().zip(&collide.contacts) {
                let mut points = [[f64::NAN; 3]; 6];
                for (p, q) in points.iter_mut().zip(c.intersection.points()) {
                    *p = (*q).into();
                }
                slot.write(ObbtreeContact {
                    tri_a: c.tri_a,
                    tri_b: c.tri_b,
                    coplanar: c.intersection.kind == IntersectionKind::Polygon,
                    point_count: c.intersection.points().len() as u32,
                    points,
                    residual: c.intersection.residual,
                });
            }
            Ok((
                collide.contacts.len(),
                collide.curve_length(),
                collide.overlap_area(),
            ))
        };
        // SAFETY: NULL or a live handle (the caller's contract).
        let (n, length, area) = unsafe { with_pair(pair, query) }?;
        for (ptr, value, name) in [
            (curve_length, length, "curve_length"),
            (overlap_area, area, "overlap_area"),
        ] {
            if !ptr.is_null() {
                // SAFETY: non-NULL, so writable (the caller's contract).
                unsafe { slot(ptr, name) }?.write(value);
            }
        }
        if !count.is_null() {
            // SAFETY: non-NULL, so writable (the caller's contract).
            unsafe { slot(count, "count") }?.write(n);
        }
        if n > capacity && !totals_only {
            return Err(Error::new(
                ObbtreeStatus::BufferTooSmall,
                format!("the contacts buffer holds {capacity} contacts but {n} are needed"),
            ));
        }
        Ok(())
    })
}
