//! The broad phase: sweep and prune (I-COLLIDE's), kept sorted by insertion sort from one
//! frame to the next.
//!
//! Each object is an axis-aligned box. Along the two axes on which the boxes spread most
//! (chosen once, from the first boxes), the boxes' 2N endpoints are kept sorted: after
//! boxes move, an insertion sort restores the order with one adjacent move per pair of
//! endpoints whose order changed, so coherent motion costs O(N + changes). A crossing that
//! puts a box's minimum before another's maximum may start an overlap on that axis (the
//! pair joins the *planar* set if the boxes now overlap on both sorted axes); one that
//! puts a maximum before a minimum ends it. The third axis, where boxes are densest (a
//! robot cell or a game level is wide and flat), is not sorted: the planar pairs are
//! checked on it each frame, which costs less than the crossings sorting it would take.
//! No per-axis overlap counts are stored, so memory stays O(N + planar pairs).

use rustc_hash::FxHashMap;

/// An axis-aligned box: `[min, max]`, `min[k] <= max[k]`, finite.
pub type Bounds = [[f64; 3]; 2];

/// One end of a box along a sorted axis: `tag` is `object << 1 | is_max`; `key` orders
/// endpoints with one integer comparison (see [`sort_key`]).
#[derive(Clone, Copy, Debug)]
struct Endpoint {
    key: u64,
    tag: u32,
}

impl Endpoint {
    fn object(self) -> u32 {
        self.tag >> 1
    }
    fn is_max(self) -> bool {
        self.tag & 1 == 1
    }
}

/// An integer that orders as `value` does, with the last bit replaced by the end's kind,
/// so that a minimum sorts before a maximum of equal value (touching boxes overlap). The
/// last mantissa bit is lost: values one unit in the last place apart may tie, and a tie
/// counts as overlapping, so the broad phase errs only towards reporting a pair.
fn sort_key(value: f64, is_max: bool) -> u64 {
    let bits = value.to_bits();
    let ordered = if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    };
    (ordered & !1) | u64::from(is_max)
}

/// Sweep and prune over a fixed set of objects `0..n`.
#[derive(Clone, Debug)]
pub struct SweepAndPrune {
    boxes: Vec<Bounds>,
    /// The two sorted axes, then the checked one.
    order: [usize; 3],
    /// Per sorted axis, the endpoints in order.
    ends: [Vec<Endpoint>; 2],
    /// Wanted pairs whose boxes overlap on both sorted axes, and whether they also overlap
    /// on the third (as of the last update).
    planar: FxHashMap<(u32, u32), bool>,
    /// How many planar pairs overlap on the third axis too.
    count: usize,
    added: Vec<(u32, u32)>,
    removed: Vec<(u32, u32)>,
}

/// Whether two boxes overlap along `axis` (touching counts).
fn overlap_on(a: &Bounds, b: &Bounds, axis: usize) -> bool {
    let [a0, a1] = a.map(|end| end.get(axis).copied().unwrap_or(f64::NAN));
    let [b0, b1] = b.map(|end| end.get(axis).copied().unwrap_or(f64::NAN));
    a0 <= b1 && b0 <= a1
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The axis of sorted list `sorted` (0 or 1) and the other sorted axis.
fn sorted_axes(order: [usize; 3], sorted: usize) -> (usize, usize) {
    let [first, second, _] = order;
    if sorted == 0 {
        (first, second)
    } else {
        (second, first)
    }
}

/// Gives each endpoint its box's current value on `axis`.
fn refresh(list: &mut [Endpoint], boxes: &[Bounds], axis: usize) {
    for e in list {
        let end = boxes
            .get(e.object() as usize)
            .and_then(|b| b.get(usize::from(e.is_max())));
        let value = end.and_then(|v| v.get(axis)).copied().unwrap_or(f64::NAN);
        e.key = sort_key(value, e.is_max());
    }
}

/// The axes by decreasing spread of the boxes' centres.
fn spread_order(boxes: &[Bounds]) -> [usize; 3] {
    let n = boxes.len().max(1) as f64;
    let mut spread = [0.0f64; 3];
    for (k, s) in spread.iter_mut().enumerate() {
        let centre = |b: &Bounds| b.iter().filter_map(|end| end.get(k)).sum::<f64>() * 0.5;
        let mean = boxes.iter().map(centre).sum::<f64>() / n;
        *s = boxes
            .iter()
            .map(|b| (centre(b) - mean).powi(2))
            .sum::<f64>();
    }
    let mut order = [0, 1, 2];
    order.sort_by(|&x, &y| {
        let (sx, sy) = (spread.get(x).copied(), spread.get(y).copied());
        sy.partial_cmp(&sx).unwrap_or(std::cmp::Ordering::Equal)
    });
    order
}

impl SweepAndPrune {
    /// The broad phase of `boxes` (object `i` is `boxes[i]`); `wanted(i, j)` (with
    /// `i < j`) filters which overlapping pairs are kept. Non-finite boxes are the
    /// caller's to refuse: they never overlap anything.
    pub fn new(boxes: Vec<Bounds>, wanted: impl Fn(u32, u32) -> bool) -> SweepAndPrune {
        let order = spread_order(&boxes);
        let mut ends: [Vec<Endpoint>; 2] = Default::default();
        for (sorted, list) in ends.iter_mut().enumerate() {
            for i in 0..boxes.len() as u32 {
                list.push(Endpoint {
                    key: 0,
                    tag: i << 1,
                });
                list.push(Endpoint {
                    key: 0,
                    tag: i << 1 | 1,
                });
            }
            refresh(list, &boxes, sorted_axes(order, sorted).0);
            list.sort_unstable_by_key(|e| (e.key, e.tag));
        }
        let mut sap = SweepAndPrune {
            boxes,
            order,
            ends,
            planar: FxHashMap::default(),
            count: 0,
            added: Vec::new(),
            removed: Vec::new(),
        };
        // The first planar pairs, by one sweep along the first axis.
        let mut active: Vec<u32> = Vec::new();
        let [first, _] = &sap.ends;
        for e in first {
            if e.is_max() {
                active.retain(|&o| o != e.object());
                continue;
            }
            for &o in &active {
                let (a, b) = key(o, e.object());
                if sap.overlap(a, b, sap.order[1]) && wanted(a, b) {
                    sap.planar.insert((a, b), false);
                }
            }
            active.push(e.object());
        }
        sap.added.clear();
        sap.removed.clear();
        sap.check_third_axis();
        sap
    }

    fn overlap(&self, a: u32, b: u32, axis: usize) -> bool {
        match (self.boxes.get(a as usize), self.boxes.get(b as usize)) {
            (Some(x), Some(y)) => overlap_on(x, y, axis),
            _ => false,
        }
    }

    /// Moves object `object`'s box; takes effect at the next [`SweepAndPrune::update`].
    pub fn set_box(&mut self, object: u32, bounds: Bounds) {
        if let Some(b) = self.boxes.get_mut(object as usize) {
            *b = bounds;
        }
    }

    /// Restores the order along the sorted axes after boxes moved, and updates the
    /// overlapping pairs; [`SweepAndPrune::added`] and [`SweepAndPrune::removed`] then say
    /// what changed.
    pub fn update(&mut self, wanted: impl Fn(u32, u32) -> bool) {
        self.added.clear();
        self.removed.clear();
        let mut ends = std::mem::take(&mut self.ends);
        for (sorted, list) in ends.iter_mut().enumerate() {
            let (axis, other_axis) = sorted_axes(self.order, sorted);
            // Endpoints take their boxes' new values in one pass, then an insertion sort
            // restores the order, with one crossing per pair whose order changed.
            refresh(list, &self.boxes, axis);
            for i in 1..list.len() {
                let Some((head, tail)) = list.split_at_checked(i) else {
                    break;
                };
                let Some(&moving) = tail.first() else { break };
                let passed = head.iter().rev().take_while(|o| moving.key < o.key).count();
                if passed == 0 {
                    continue;
                }
                let start = i - passed;
                for &other in head.get(start..).unwrap_or(&[]) {
                    if other.is_max() != moving.is_max() {
                        self.crossed(moving, other, other_axis, &wanted);
                    }
                }
                if let Some(run) = list.get_mut(start..=i) {
                    run.rotate_right(1);
                }
            }
        }
        self.ends = ends;
        self.check_third_axis();
    }

    /// `moving` has just passed `other` towards smaller values along a sorted axis.
    fn crossed(
        &mut self,
        moving: Endpoint,
        other: Endpoint,
        other_axis: usize,
        wanted: &impl Fn(u32, u32) -> bool,
    ) {
        if moving.object() == other.object() {
            return;
        }
        let pair = key(moving.object(), other.object());
        if moving.is_max() {
            // A maximum before another's minimum: apart along this axis.
            if self.planar.remove(&pair) == Some(true) {
                self.count = self.count.saturating_sub(1);
                self.removed.push(pair);
            }
        } else if self.overlap(pair.0, pair.1, other_axis) && wanted(pair.0, pair.1) {
            // A minimum before another's maximum, and overlapping on the other sorted axis.
            self.planar.entry(pair).or_insert(false);
        }
    }

    /// Checks every planar pair on the third axis, recording what changed.
    fn check_third_axis(&mut self) {
        let third = self.order[2];
        let boxes = &self.boxes;
        for (&(a, b), inside) in self.planar.iter_mut() {
            let now = match (boxes.get(a as usize), boxes.get(b as usize)) {
                (Some(x), Some(y)) => overlap_on(x, y, third),
                _ => false,
            };
            if now != *inside {
                *inside = now;
                if now {
                    self.count += 1;
                    self.added.push((a, b));
                } else {
                    self.count = self.count.saturating_sub(1);
                    self.removed.push((a, b));
                }
            }
        }
    }

    /// The wanted pairs whose boxes overlap, `(i, j)` with `i < j`, in no particular order.
    pub fn overlaps(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.planar
            .iter()
            .filter_map(|(&pair, &inside)| inside.then_some(pair))
    }

    /// How many wanted pairs overlap.
    pub fn overlap_count(&self) -> usize {
        self.count
    }

    /// Whether the pair `(i, j)` (`i < j`) is among the overlapping wanted pairs.
    pub fn contains(&self, pair: (u32, u32)) -> bool {
        self.planar.get(&pair) == Some(&true)
    }

    /// Pairs that began to overlap in the last update (all of them after `new`).
    pub fn added(&self) -> &[(u32, u32)] {
        &self.added
    }

    /// Pairs that stopped overlapping in the last update.
    pub fn removed(&self) -> &[(u32, u32)] {
        &self.removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sorted axes are those the centres spread along most, measured about their mean:
    /// a row of boxes far from the origin along x, spread widely along y and less along z,
    /// sorts y, then z, and leaves x (where a mean taken wrong would see x's offset as
    /// spread) to be checked.
    #[test]
    fn the_axes_of_widest_spread_are_sorted() {
        let boxes: Vec<Bounds> = (0..8)
            .map(|i| {
                let c = [
                    1e3 + 0.01 * f64::from(i % 2),
                    3.0 * f64::from(i),
                    f64::from(i % 3),
                ];
                [c.map(|x| x - 0.1), c.map(|x| x + 0.1)]
            })
            .collect();
        assert_eq!(spread_order(&boxes), [1, 2, 0]);
        let sap = SweepAndPrune::new(boxes, |_, _| true);
        assert_eq!(sap.order, [1, 2, 0]);
    }
}
