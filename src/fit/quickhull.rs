//! 3-D quickhull: the triangulated convex-hull surface of a full-dimensional point set.
//!
//! Robustness is bought with a plane tolerance `eps` and a few local repairs rather than
//! exact arithmetic, since the hull only feeds a covariance (the box extents are later
//! taken over all vertices, so a point the hull misses by `eps` costs nothing):
//! * a point counts as outside a face only when it is more than `eps` above it, so
//!   points within about `eps` of the hull may be left out;
//! * before a cone is built, hidden faces that the apex is above by less than `eps`, or
//!   that the new face would fold over, are absorbed into the visible region, and a
//!   visible region that rounding made pinched or holed is grown until it is a disc —
//!   this keeps the surface convex to within a few `eps`;
//! * every new edge is checked as it is made; a clearly reflex or folded edge means the
//!   construction went wrong, and is reported as an error (the fit then falls back to
//!   the triangle covariance) rather than returned as a hull that could be wrong by its
//!   whole diameter.
//!
//! Nothing here panics or loops: each iteration consumes one outside point for good, so
//! the loop ends after at most as many iterations as there are points.

use crate::arr3::{cross, dot, norm2, sub, V3};

/// Marks an absent point or face.
const NONE: u32 = u32::MAX;

/// A cone edge more reflex than this many `eps` means rounding broke the surface: the
/// hull fails.
const CONVEX_MARGIN: f64 = 1000.0;

/// Two faces with opposed normals whose far vertices are within this many `eps` of each
/// other's planes are folded flat onto each other: the hull fails.
const FOLD_MARGIN: f64 = 4.0;

/// How many rounds one iteration may grow its visible region to repair it.
const MAX_REPAIRS: u32 = 64;

/// Why the hull could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum QuickHullError {
    /// Fewer than four points, too many to index with `u32`, or a bad seed simplex.
    Input,
    /// Floating-point trouble broke the surface's topology.
    Numerical,
}

/// A hull triangle, counter-clockwise seen from outside.
#[derive(Clone, Copy, Debug)]
struct Face {
    v: [u32; 3],
    /// `adj[i]` is the face across the edge `v[i] → v[(i + 1) % 3]`.
    adj: [u32; 3],
    /// Outward normal, *not* normalised (twice the area as length): the outside test
    /// compares squares instead, so building a face needs no square root or division.
    normal: V3,
    /// `normal · x` on the plane.
    offset: f64,
    /// `(eps · |normal|)²`: a point with height `h = normal · x − offset > 0` is outside
    /// when `h² > threshold`, i.e. more than `eps` above the plane.
    threshold: f64,
    /// Head of this face's list of outside points (linked through `QuickHull::next`).
    head: u32,
    /// The outside point farthest above the plane, and its (scaled) height.
    far: u32,
    far_dist: f64,
    /// Iteration in which the face was last examined, and what was found then.
    mark: u32,
    visible: bool,
    alive: bool,
}

/// A horizon edge `a → b` (as oriented in the visible face) and the hidden face across it.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: u32,
    b: u32,
    across: u32,
}

/// Reusable buffers for [`QuickHull::run`]; keeping them across calls avoids allocating
/// in the many small hulls of a tree build.
#[derive(Debug, Default)]
pub(crate) struct QuickHull {
    faces: Vec<Face>,
    free: Vec<u32>,
    next: Vec<u32>,
    pending: Vec<u32>,
    stack: Vec<u32>,
    visible: Vec<u32>,
    horizon: Vec<Edge>,
    ordered: Vec<Edge>,
    new_faces: Vec<u32>,
    slot: Vec<u32>,
    slot_mark: Vec<u32>,
    /// Stamp of the current `chain_horizon` attempt in `slot_mark`.
    chain: u32,
    /// Set by `find_visible` when some hidden neighbour is within `eps` of the apex.
    suspicious: bool,
    iteration: u32,
}

impl QuickHull {
    /// Computes the hull of `points` into `out` (indices into `points`, counter-clockwise
    /// seen from outside).
    ///
    /// `simplex` must be four affinely independent points of the set with the fourth more
    /// than `eps` from the plane of the first three (as produced by the dimension check);
    /// `eps` is the absolute plane tolerance. Coordinates should be centred near the
    /// origin so that plane offsets carry little rounding.
    pub(crate) fn run(
        &mut self,
        points: &[V3],
        simplex: [usize; 4],
        eps: f64,
        out: &mut Vec<[u32; 3]>,
    ) -> Result<(), QuickHullError> {
        out.clear();
        let n = points.len();
        if n < 4 || n >= NONE as usize || eps.is_nan() || eps < 0.0 {
            return Err(QuickHullError::Input);
        }
        if n == 4 {
            // Four affinely independent points: the hull is the seed tetrahedron itself.
            for (v, _) in seed_faces(points, simplex)? {
                out.push(v);
            }
            return Ok(());
        }
        self.faces.clear();
        self.free.clear();
        self.pending.clear();
        // Per-point buffers need no clearing: `next` is written before it is read, `slot`
        // is only read where `slot_mark` holds the current stamp, and stamps only grow.
        if self.next.len() < n {
            self.next.resize(n, NONE);
            self.slot.resize(n, NONE);
            self.slot_mark.resize(n, 0);
        }
        self.iteration = 0;

        self.seed(points, simplex, eps)?;
        // Initial assignment: every other point goes to the first face it is outside of;
        // points inside the tetrahedron are dropped for good.
        for (i, &p) in points.iter().enumerate() {
            if simplex.contains(&i) {
                continue;
            }
            for f in 0..4u32 {
                if let Some(d) = self.faces[f as usize].outside(p) {
                    self.push_outside(f, i as u32, d);
                    break;
                }
            }
        }
        for f in 0..4u32 {
            if self.faces[f as usize].head != NONE {
                self.pending.push(f);
            }
        }

        // Each iteration turns one outside point into a hull vertex and never sees it
        // again, so at most `n` iterations happen; the bound is a second guard.
        let mut budget = n;
        while let Some(f) = self.pending.pop() {
            let face = &self.faces[f as usize];
            if !face.alive || face.head == NONE {
                continue;
            }
            let apex = face.far;
            if budget == 0 {
                return Err(QuickHullError::Numerical);
            }
            budget -= 1;
            self.add_point(points, f, apex, eps)?;
        }

        out.extend(self.faces.iter().filter(|f| f.alive).map(|f| f.v));
        Ok(())
    }

    /// Builds the four faces of the seed tetrahedron, oriented outwards, with adjacency.
    fn seed(&mut self, points: &[V3], s: [usize; 4], eps: f64) -> Result<(), QuickHullError> {
        for (k, (v, adj)) in seed_faces(points, s)?.into_iter().enumerate() {
            // The faces were cleared, so the seed's faces are 0 to 3, in order.
            let f = self.new_face(points, v, eps)?;
            debug_assert_eq!(f as usize, k);
            self.faces[f as usize].adj = adj;
        }
        Ok(())
    }

    /// Allocates a face (reusing a freed slot) with its plane; no adjacency, no points.
    fn new_face(&mut self, points: &[V3], v: [u32; 3], eps: f64) -> Result<u32, QuickHullError> {
        let (a, b, c) = (
            points[v[0] as usize],
            points[v[1] as usize],
            points[v[2] as usize],
        );
        let normal = cross(sub(b, a), sub(c, a));
        let len2 = norm2(normal);
        if !(len2 > 0.0 && len2.is_finite()) {
            return Err(QuickHullError::Numerical);
        }
        // The centroid as the plane's anchor spreads the rounding over the three vertices.
        let sum = [a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]];
        let face = Face {
            v,
            adj: [NONE; 3],
            normal,
            offset: dot(normal, sum) * (1.0 / 3.0),
            threshold: eps * eps * len2,
            head: NONE,
            far: NONE,
            far_dist: 0.0,
            mark: 0,
            visible: false,
            alive: true,
        };
        if let Some(slot) = self.free.pop() {
            self.faces[slot as usize] = face;
            return Ok(slot);
        }
        if self.faces.len() >= NONE as usize - 1 {
            return Err(QuickHullError::Numerical);
        }
        self.faces.push(face);
        Ok((self.faces.len() - 1) as u32)
    }

    /// Adds point `p` at height `d` to the outside list of face `f`.
    #[inline]
    fn push_outside(&mut self, f: u32, p: u32, d: f64) {
        let face = &mut self.faces[f as usize];
        self.next[p as usize] = face.head;
        face.head = p;
        if face.far == NONE || d > face.far_dist {
            face.far = p;
            face.far_dist = d;
        }
    }

    /// Makes `apex` (the farthest outside point of face `start`) a hull vertex.
    fn add_point(
        &mut self,
        points: &[V3],
        start: u32,
        apex: u32,
        eps: f64,
    ) -> Result<(), QuickHullError> {
        let apex_p = points[apex as usize];
        self.iteration = self.iteration.wrapping_add(1);
        let it = self.iteration;
        self.find_visible(apex_p, start, it)?;
        // Two repairs keep the cone consistent in floating point:
        // * a hidden face that the apex is above, however slightly, or that the new face
        //   on its edge would fold over (nearly coplanar, overlapping, normals opposed),
        //   is absorbed into the visible region: otherwise the surface gets a reflex or
        //   folded edge and later visibility tests contradict each other;
        // * rounding among coplanar faces can make the visible region touch itself at a
        //   vertex or enclose a hidden face; absorbing the horizon faces nearly coplanar
        //   with the apex, with a margin doubling each round up to 16 `eps`, repairs that.
        // Each round absorbs at least one face. A valid loop is kept when the budget runs
        // out; a region that still is not a disc is an error.
        let mut rounds = 0;
        loop {
            if self.chain_horizon() {
                if !self.suspicious
                    || rounds >= MAX_REPAIRS
                    || !self.absorb_folds(points, apex_p, it)
                {
                    break;
                }
            } else {
                let margin = f64::from(1u32 << (rounds + 1).min(4));
                if rounds >= MAX_REPAIRS || !self.absorb_coplanar(apex_p, it, margin) {
                    return Err(QuickHullError::Numerical);
                }
                // The new horizon faces have not been screened for folds.
                self.suspicious = true;
            }
            rounds += 1;
        }

        // A cone of new faces from the horizon to the apex; the horizon is ordered so
        // that edge k ends where edge k + 1 starts.
        self.new_faces.clear();
        for k in 0..self.horizon.len() {
            let e = self.horizon[k];
            let f = self.new_face(points, [e.a, e.b, apex], eps)?;
            self.new_faces.push(f);
        }
        // Link the cone, checking each new edge as it is made: the neighbour's far
        // vertex must not be clearly above the new face (reflex), nor flat against it
        // with opposed normals (folded). The repairs above can leave edges reflex by a
        // few `eps`; anything more means rounding broke the surface, which would go on
        // to make the hull wrong by up to its diameter. Every edge of the final hull is
        // checked once, when it is made.
        let limit = CONVEX_MARGIN * CONVEX_MARGIN * eps * eps;
        let flat = FOLD_MARGIN * FOLD_MARGIN * eps * eps;
        let h = self.new_faces.len();
        let mut prev_f = self.new_faces.last().copied().unwrap_or(NONE);
        for k in 0..h {
            // Neighbours in the cone, without `%` (an integer division per edge).
            let next = if k + 1 < h { k + 1 } else { 0 };
            let (f, e) = (self.new_faces[k], self.horizon[k]);
            let (next_f, next_b) = (self.new_faces[next], self.horizon[next].b);
            let (across, face, following) = (
                &self.faces[e.across as usize],
                &self.faces[f as usize],
                &self.faces[next_f as usize],
            );
            // A horizon edge whose hidden face lacks it means broken adjacency.
            let (j, far) = find_edge(&across.v, e.b, e.a).ok_or(QuickHullError::Numerical)?;
            let (w, c) = (points[far as usize], points[next_b as usize]);
            if broken_edge(face, across.normal, w, limit, flat)
                || broken_edge(face, following.normal, c, limit, flat)
            {
                return Err(QuickHullError::Numerical);
            }
            self.faces[e.across as usize].adj[j] = f;
            self.faces[f as usize].adj = [e.across, next_f, prev_f];
            prev_f = f;
        }

        // Hand the outside points of the doomed faces to the new ones.
        for vi in 0..self.visible.len() {
            let mut p = self.faces[self.visible[vi] as usize].head;
            while p != NONE {
                let following = self.next[p as usize];
                if p != apex {
                    let q = points[p as usize];
                    for k in 0..h {
                        let f = self.new_faces[k];
                        if let Some(d) = self.faces[f as usize].outside(q) {
                            self.push_outside(f, p, d);
                            break;
                        }
                    }
                }
                p = following;
            }
        }
        for &g in &self.visible {
            let face = &mut self.faces[g as usize];
            face.alive = false;
            face.head = NONE;
            self.free.push(g);
        }
        for &f in &self.new_faces {
            if self.faces[f as usize].head != NONE {
                self.pending.push(f);
            }
        }
        Ok(())
    }

    /// Floods the faces that see `apex` (more than `eps` below it) from `start`, and
    /// collects the edges between seen and unseen faces into `self.horizon`.
    fn find_visible(&mut self, apex: V3, start: u32, it: u32) -> Result<(), QuickHullError> {
        self.visible.clear();
        self.horizon.clear();
        self.stack.clear();
        self.suspicious = false;
        let first = &mut self.faces[start as usize];
        first.mark = it;
        first.visible = true;
        self.stack.push(start);
        while let Some(g) = self.stack.pop() {
            self.visible.push(g);
            let Face { v, adj, .. } = self.faces[g as usize];
            for (a, b, h) in edges(v, adj) {
                let hf = &mut self.faces[h as usize];
                // A dead face still linked: the repairs broke the adjacency.
                if !hf.alive {
                    return Err(QuickHullError::Numerical);
                }
                if hf.mark != it {
                    hf.mark = it;
                    let d = dot(hf.normal, apex) - hf.offset;
                    let d2 = d * d;
                    hf.visible = d > 0.0 && d2 > hf.threshold;
                    // Hidden, yet the apex is above it or within `eps` below: the cone
                    // may need the fold repair.
                    self.suspicious |= !hf.visible && (d > 0.0 || d2 <= hf.threshold);
                    if hf.visible {
                        self.stack.push(h);
                        continue;
                    }
                }
                if !hf.visible {
                    self.horizon.push(Edge { a, b, across: h });
                }
            }
        }
        Ok(())
    }

    /// Orders the horizon edges into one closed loop; false if they do not form exactly
    /// one (a visible region that is not a disc).
    fn chain_horizon(&mut self) -> bool {
        let h = self.horizon.len();
        if h < 3 {
            return false;
        }
        self.chain = self.chain.wrapping_add(1);
        if self.chain == 0 {
            self.slot_mark.fill(0);
            self.chain = 1;
        }
        let stamp = self.chain;
        for (k, e) in self.horizon.iter().enumerate() {
            let a = e.a as usize;
            if self.slot_mark[a] == stamp {
                // Two horizon edges leave the same vertex: the loop is pinched.
                return false;
            }
            self.slot_mark[a] = stamp;
            self.slot[a] = k as u32;
        }
        // Walk the loop from edge 0. Returning to edge 0 first after exactly h steps
        // means every edge was visited once: the horizon is a single closed loop.
        self.ordered.clear();
        let mut k = 0usize;
        for step in 0..h {
            if step > 0 && k == 0 {
                return false;
            }
            let e = self.horizon[k];
            self.ordered.push(e);
            let b = e.b as usize;
            if self.slot_mark[b] != stamp {
                // No horizon edge leaves where this one ends: the loop is open.
                return false;
            }
            k = self.slot[b] as usize;
        }
        if k != 0 {
            return false;
        }
        std::mem::swap(&mut self.ordered, &mut self.horizon);
        true
    }

    /// Adds to the visible region the hidden faces across the horizon that are less than
    /// `margin · eps` below `apex`, and recomputes the horizon. Returns false if there
    /// were none, so the repair cannot progress.
    fn absorb_coplanar(&mut self, apex: V3, it: u32, margin: f64) -> bool {
        let mut grown = false;
        for k in 0..self.horizon.len() {
            let h = self.horizon[k].across;
            let face = &mut self.faces[h as usize];
            // Faces first reached by an earlier repair round have not been examined yet.
            if face.mark != it || !face.visible {
                face.mark = it;
                face.visible = face.near(apex, margin);
                if face.visible {
                    self.visible.push(h);
                    grown = true;
                }
            }
        }
        if grown {
            self.rebuild_horizon(it);
        }
        grown
    }

    /// Adds to the visible region the hidden faces across the horizon that the apex is
    /// above, or within `eps` below and overlapped by the new face on their edge (the
    /// new face's normal opposes theirs), and recomputes the horizon. Returns false if
    /// there were none.
    fn absorb_folds(&mut self, points: &[V3], apex: V3, it: u32) -> bool {
        let mut grown = false;
        for k in 0..self.horizon.len() {
            let e = self.horizon[k];
            let (a, b) = (points[e.a as usize], points[e.b as usize]);
            let face = &mut self.faces[e.across as usize];
            if face.mark == it && face.visible {
                continue; // absorbed through an earlier edge of this round
            }
            let d = dot(face.normal, apex) - face.offset;
            let fold = d > 0.0
                || (d * d <= face.threshold
                    && dot(cross(sub(b, a), sub(apex, a)), face.normal) <= 0.0);
            if fold {
                face.mark = it;
                face.visible = true;
                self.visible.push(e.across);
                grown = true;
            }
        }
        if grown {
            self.rebuild_horizon(it);
        }
        grown
    }

    /// Recomputes the (unordered) horizon of the visible faces.
    fn rebuild_horizon(&mut self, it: u32) {
        self.horizon.clear();
        for &g in &self.visible {
            let Face { v, adj, .. } = self.faces[g as usize];
            for (a, b, across) in edges(v, adj) {
                let x = &self.faces[across as usize];
                if !(x.mark == it && x.visible) {
                    self.horizon.push(Edge { a, b, across });
                }
            }
        }
    }
}

impl Face {
    /// True unless `p` is more than `margin · eps` below the plane.
    #[inline(always)]
    fn near(&self, p: V3, margin: f64) -> bool {
        let h = dot(self.normal, p) - self.offset;
        h > 0.0 || h * h <= margin * margin * self.threshold
    }

    /// The scaled height of `p` above the plane if it is more than `eps` above it.
    #[inline(always)]
    fn outside(&self, p: V3) -> Option<f64> {
        let h = dot(self.normal, p) - self.offset;
        (h > 0.0 && h * h > self.threshold).then_some(h)
    }
}

/// True when the edge between `face` and a neighbour (its unnormalised `normal`, and
/// its vertex `far` off the shared edge) is clearly reflex (`far` more than `√limit`
/// above the face, in units of `eps²`-scaled squares as in [`Face::threshold`]) or
/// folded (`far` within `√flat` of the face's plane while the normals oppose).
#[inline(always)]
fn broken_edge(face: &Face, normal: V3, far: V3, limit: f64, flat: f64) -> bool {
    let d = dot(face.normal, far) - face.offset;
    let len2 = norm2(face.normal);
    let d2 = d * d;
    if d > 0.0 && d2 > limit * len2 {
        return true; // reflex
    }
    // Folded: flat against the face with opposed normals (the dot product is only needed
    // for the rare nearly flat edge).
    d2 <= flat * len2 && dot(face.normal, normal) < 0.0
}

/// The faces of the tetrahedron on `s` (indices into `points`), counter-clockwise seen
/// from outside, each with the faces across its edges (as in [`Face::adj`]). Face `k`
/// leaves out `s[3 - k]`, so the face across an edge is the one that leaves out the third
/// vertex of the face on this side. Fails on an index out of range or a face of zero
/// area.
#[allow(clippy::type_complexity)]
fn seed_faces(points: &[V3], s: [usize; 4]) -> Result<[([u32; 3], [u32; 3]); 4], QuickHullError> {
    // Point `s[k]`, and its index as a `u32`.
    let at = |k: usize| s.get(k).copied().ok_or(QuickHullError::Input);
    let pt = |k: usize| {
        let i = at(k)?;
        points.get(i).copied().ok_or(QuickHullError::Input)
    };
    let id = |k: usize| u32::try_from(at(k)?).map_err(|_| QuickHullError::Input);
    // Each face with the vertex it must face away from, as positions in `s`.
    let combos = [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)];
    let mut faces = [([0; 3], [0; 3]); 4];
    for (face, (a, mut b, mut c, o)) in faces.iter_mut().zip(combos) {
        let (pa, pb, pc, po) = (pt(a)?, pt(b)?, pt(c)?, pt(o)?);
        let normal = cross(sub(pb, pa), sub(pc, pa));
        if dot(normal, sub(po, pa)) > 0.0 {
            std::mem::swap(&mut b, &mut c);
        }
        let len2 = norm2(normal);
        if !(len2 > 0.0 && len2.is_finite()) {
            return Err(QuickHullError::Numerical);
        }
        *face = (
            [id(a)?, id(b)?, id(c)?],
            [3 - c as u32, 3 - a as u32, 3 - b as u32],
        );
    }
    Ok(faces)
}

/// Position `j` with `v[j] == a` and `v[(j + 1) % 3] == b`, if the triangle has that edge,
/// and the third vertex `v[(j + 2) % 3]`.
#[inline]
fn find_edge(v: &[u32; 3], a: u32, b: u32) -> Option<(usize, u32)> {
    if v[0] == a && v[1] == b {
        Some((0, v[2]))
    } else if v[1] == a && v[2] == b {
        Some((1, v[0]))
    } else if v[2] == a && v[0] == b {
        Some((2, v[1]))
    } else {
        None
    }
}

/// The edges `v[i] → v[(i + 1) % 3]` of a face with the face across each (`adj[i]`).
#[inline(always)]
fn edges(v: [u32; 3], adj: [u32; 3]) -> [(u32, u32, u32); 3] {
    [
        (v[0], v[1], adj[0]),
        (v[1], v[2], adj[1]),
        (v[2], v[0], adj[2]),
    ]
}
