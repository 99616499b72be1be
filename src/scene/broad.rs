//! The broad phase: sweep and prune on three axes (I-COLLIDE's), kept sorted by insertion
//! sort from one frame to the next.
//!
//! Each object is an axis-aligned box; along each axis the boxes' 2N endpoints are kept
//! sorted. After boxes move, an insertion sort restores the order with one adjacent swap
//! per pair of endpoints whose order changed, so coherent motion costs O(N + changes). A
//! swap that puts a box's minimum before another's maximum may start an overlap (the pair
//! is added if the boxes now overlap on all three axes); one that puts a maximum before a
//! minimum ends it on that axis (the pair is removed). No overlap counts are stored, so
//! memory stays O(N + overlapping pairs) even when most boxes overlap on one axis.

use rustc_hash::FxHashSet;

/// An axis-aligned box: `min[k] <= max[k]`, finite.
pub type Bounds = [[f64; 3]; 2];

/// One end of a box along an axis: `tag` is `object << 1 | is_max`.
#[derive(Clone, Copy, Debug)]
struct Endpoint {
    value: f64,
    tag: u32,
}

impl Endpoint {
    fn object(self) -> u32 {
        self.tag >> 1
    }
    fn is_max(self) -> bool {
        self.tag & 1 == 1
    }
    /// Sort order: by value, a minimum before a maximum of equal value (touching boxes
    /// overlap).
    fn before(self, other: Endpoint) -> bool {
        self.value < other.value || (self.value == other.value && !self.is_max() && other.is_max())
    }
}

/// One axis: the endpoints in order, and where each endpoint (by tag) is.
#[derive(Clone, Debug, Default)]
struct Axis {
    ends: Vec<Endpoint>,
    slots: Vec<u32>,
}

/// Sweep and prune over a fixed set of objects `0..n`.
#[derive(Clone, Debug)]
pub struct SweepAndPrune {
    boxes: Vec<Bounds>,
    axes: [Axis; 3],
    overlaps: FxHashSet<(u32, u32)>,
    added: Vec<(u32, u32)>,
    removed: Vec<(u32, u32)>,
}

fn overlap(a: &Bounds, b: &Bounds) -> bool {
    let below = |lo: &[f64; 3], hi: &[f64; 3]| lo.iter().zip(hi).all(|(l, h)| l <= h);
    below(&a[0], &b[1]) && below(&b[0], &a[1])
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl SweepAndPrune {
    /// The broad phase of `boxes` (object `i` is `boxes[i]`); `wanted(i, j)` (with
    /// `i < j`) filters which overlapping pairs are kept. Non-finite boxes are the
    /// caller's to refuse: they never overlap anything.
    pub fn new(boxes: Vec<Bounds>, wanted: impl Fn(u32, u32) -> bool) -> SweepAndPrune {
        let mut axes: [Axis; 3] = Default::default();
        for (k, axis) in axes.iter_mut().enumerate() {
            for (i, b) in (0u32..).zip(&boxes) {
                let [lo, hi] = b.map(|end| end.get(k).copied().unwrap_or(f64::NAN));
                axis.ends.push(Endpoint {
                    value: lo,
                    tag: i << 1,
                });
                axis.ends.push(Endpoint {
                    value: hi,
                    tag: i << 1 | 1,
                });
            }
            axis.ends.sort_by(|x, y| {
                x.value
                    .total_cmp(&y.value)
                    .then(x.is_max().cmp(&y.is_max()))
            });
            axis.slots = vec![0; axis.ends.len()];
            for (position, e) in (0u32..).zip(&axis.ends) {
                if let Some(s) = axis.slots.get_mut(e.tag as usize) {
                    *s = position;
                }
            }
        }
        let mut sap = SweepAndPrune {
            boxes,
            axes,
            overlaps: FxHashSet::default(),
            added: Vec::new(),
            removed: Vec::new(),
        };
        // The first overlaps, by one sweep along x.
        let mut active: Vec<u32> = Vec::new();
        let [x, ..] = &sap.axes;
        for e in &x.ends {
            if e.is_max() {
                active.retain(|&o| o != e.object());
                continue;
            }
            for &o in &active {
                let (a, b) = key(o, e.object());
                let (Some(ba), Some(bb)) = (sap.boxes.get(a as usize), sap.boxes.get(b as usize))
                else {
                    continue;
                };
                if overlap(ba, bb) && wanted(a, b) {
                    sap.overlaps.insert((a, b));
                }
            }
            active.push(e.object());
        }
        sap.added = sap.overlaps.iter().copied().collect();
        sap
    }

    fn boxes_overlap(&self, a: u32, b: u32) -> bool {
        match (self.boxes.get(a as usize), self.boxes.get(b as usize)) {
            (Some(x), Some(y)) => overlap(x, y),
            _ => false,
        }
    }

    /// Moves object `object`'s box; takes effect at the next [`SweepAndPrune::update`].
    pub fn set_box(&mut self, object: u32, bounds: Bounds) {
        if let Some(b) = self.boxes.get_mut(object as usize) {
            *b = bounds;
        }
        for (k, axis) in self.axes.iter_mut().enumerate() {
            for (end, values) in (0u32..).zip(&bounds) {
                let slot = axis.slots.get((object << 1 | end) as usize).copied();
                let value = values.get(k).copied().unwrap_or(f64::NAN);
                if let Some(e) = slot.and_then(|s| axis.ends.get_mut(s as usize)) {
                    e.value = value;
                }
            }
        }
    }

    /// Restores the order along each axis after boxes moved, and updates the overlapping
    /// pairs; [`SweepAndPrune::added`] and [`SweepAndPrune::removed`] then say what changed.
    pub fn update(&mut self, wanted: impl Fn(u32, u32) -> bool) {
        self.added.clear();
        self.removed.clear();
        let mut axes = std::mem::take(&mut self.axes);
        for axis in &mut axes {
            let Axis { ends, slots } = axis;
            for i in 1..ends.len() {
                let Some(&moving) = ends.get(i) else { break };
                let mut j = i;
                while let Some(&other) = j.checked_sub(1).and_then(|p| ends.get(p)) {
                    if !moving.before(other) {
                        break;
                    }
                    self.crossed(moving, other, &wanted);
                    if let Some(slot) = ends.get_mut(j) {
                        *slot = other;
                    }
                    if let Some(s) = slots.get_mut(other.tag as usize) {
                        *s = j as u32;
                    }
                    j -= 1;
                }
                if let Some(slot) = ends.get_mut(j) {
                    *slot = moving;
                }
                if let Some(s) = slots.get_mut(moving.tag as usize) {
                    *s = j as u32;
                }
            }
        }
        self.axes = axes;
    }

    /// `moving` has just passed `other` towards smaller values.
    fn crossed(&mut self, moving: Endpoint, other: Endpoint, wanted: &impl Fn(u32, u32) -> bool) {
        let pair = key(moving.object(), other.object());
        if moving.object() == other.object() {
            return;
        }
        match (moving.is_max(), other.is_max()) {
            // A minimum before another's maximum: they may now overlap.
            (false, true)
                if !self.overlaps.contains(&pair)
                    && self.boxes_overlap(pair.0, pair.1)
                    && wanted(pair.0, pair.1) =>
            {
                self.overlaps.insert(pair);
                self.added.push(pair);
            }
            // A maximum before another's minimum: apart along this axis.
            (true, false) if self.overlaps.remove(&pair) => self.removed.push(pair),
            _ => {}
        }
    }

    /// The wanted pairs whose boxes overlap, `(i, j)` with `i < j`, in no particular order.
    pub fn overlaps(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.overlaps.iter().copied()
    }

    /// How many wanted pairs overlap.
    pub fn overlap_count(&self) -> usize {
        self.overlaps.len()
    }

    /// Whether the pair `(i, j)` (`i < j`) is among the overlapping wanted pairs.
    pub fn contains(&self, pair: (u32, u32)) -> bool {
        self.overlaps.contains(&pair)
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
