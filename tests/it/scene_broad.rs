//! The broad phase reports exactly the pairs of boxes that overlap (touching included),
//! frame after frame, as brute force over all pairs says: random boxes on a grid of
//! eighths (so touching and equal coordinates are frequent), moving a little or jumping,
//! with a filter on the pairs wanted.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::indexing_slicing)]

use obbtree::scene::broad::{Bounds, SweepAndPrune};
use proptest::prelude::*;
use std::collections::BTreeSet;

fn overlapping(boxes: &[Bounds], wanted: impl Fn(u32, u32) -> bool) -> BTreeSet<(u32, u32)> {
    let mut out = BTreeSet::new();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            let (a, b) = (&boxes[i], &boxes[j]);
            let on = |k: usize| a[0][k] <= b[1][k] && b[0][k] <= a[1][k];
            if on(0) && on(1) && on(2) && wanted(i as u32, j as u32) {
                out.insert((i as u32, j as u32));
            }
        }
    }
    out
}

/// A box from grid cells: corner and size in eighths.
fn grid_box(c: [i32; 3], size: [i32; 3]) -> Bounds {
    let lo = c.map(|v| f64::from(v) / 8.0);
    let hi = std::array::from_fn(|k| f64::from(c[k] + size[k]) / 8.0);
    [lo, hi]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn overlaps_match_brute_force_every_frame(
        start in prop::collection::vec((prop::array::uniform3(0..40i32), prop::array::uniform3(0..12i32)), 1..60),
        moves in prop::collection::vec(prop::collection::vec((0..60usize, prop::array::uniform3(-3..=3i32), any::<bool>()), 0..20), 1..30),
        skip in 1..5u32,
    ) {
        let wanted = |i: u32, j: u32| !(i + j).is_multiple_of(skip) || skip == 1;
        let mut corners: Vec<[i32; 3]> = start.iter().map(|s| s.0).collect();
        let sizes: Vec<[i32; 3]> = start.iter().map(|s| s.1).collect();
        let boxes = |corners: &[[i32; 3]]| -> Vec<Bounds> {
            corners.iter().zip(&sizes).map(|(c, s)| grid_box(*c, *s)).collect()
        };
        let mut sap = SweepAndPrune::new(boxes(&corners), wanted);
        let mut current: BTreeSet<(u32, u32)> = sap.overlaps().collect();
        prop_assert_eq!(&current, &overlapping(&boxes(&corners), wanted));
        for frame in moves {
            for (object, step, jump) in frame {
                let object = object % corners.len();
                corners[object] = if jump {
                    // Incoherent: anywhere.
                    step.map(|v| (v + 3) * 6)
                } else {
                    std::array::from_fn(|k| corners[object][k] + step[k])
                };
                sap.set_box(object as u32, grid_box(corners[object], sizes[object]));
            }
            sap.update(wanted);
            let now: BTreeSet<(u32, u32)> = sap.overlaps().collect();
            prop_assert_eq!(&now, &overlapping(&boxes(&corners), wanted));
            prop_assert_eq!(sap.overlap_count(), now.len());
            // What changed is exactly the difference.
            let added: BTreeSet<_> = sap.added().iter().copied().collect();
            let removed: BTreeSet<_> = sap.removed().iter().copied().collect();
            prop_assert_eq!(added, now.difference(&current).copied().collect::<BTreeSet<_>>());
            prop_assert_eq!(removed, current.difference(&now).copied().collect::<BTreeSet<_>>());
            let n = corners.len() as u32;
            for pair in (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j))) {
                prop_assert_eq!(sap.contains(pair), now.contains(&pair), "{:?}", pair);
            }
            current = now;
        }
    }
}
