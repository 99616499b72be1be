//! Hostile `.obbt` images for the robustness suites: seeded byte flips, truncations, and
//! header, directory and node fields rewritten with extreme values, optionally re-sealed
//! (checksums recomputed) so that the damage gets past the checksums and reaches the
//! structural checks of `open` and `verify`, and the queries.
//!
//! Also [`exercise`]: open, query (unverified), verify, and when the damaged file verifies,
//! compare its collision answer with a brute force over the file's own triangles.

use obbtree::format::layout::{Field, Header, SectionEntry, ENTRY_SIZE, HEADER_SIZE};
use obbtree::format::{AlignedBytes, ObbtFile};
use obbtree::query::triangle::Triangle;
use obbtree::query::{
    CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, QueryError, SpanOptions,
    ToleranceOptions,
};

/// A library [`Field`] as (name, byte offset, width in bytes).
const fn at(field: Field) -> (&'static str, usize, usize) {
    (field.name, field.offset, field.width)
}

/// Header fields as (name, byte offset, width in bytes), from the library's [`Header::AT`].
/// The signature and the CRC are left out: rewriting them only exercises the first check.
pub const HEADER_FIELDS: [(&str, usize, usize); 20] = {
    let h = Header::AT;
    [
        at(h.version_major),
        at(h.version_minor),
        at(h.header_bytes),
        at(h.file_bytes),
        at(h.bv_kind),
        at(h.precision),
        at(h.encoding),
        at(h.fit_method),
        at(h.leaf_size),
        at(h.section_count),
        at(h.triangles),
        at(h.vertices),
        at(h.nodes),
        at(h.leaves),
        at(h.depth),
        at(h.degenerate_triangles),
        at(h.max_leaf_faces),
        at(h.reserved0),
        // One f64 of each bound: the first of the minimum, the last of the maximum.
        ("bounds_min.x", h.bounds_min.offset, 8),
        ("bounds_max.z", h.bounds_max.offset + 16, 8),
    ]
};

/// Directory entry fields as (name, offset within the entry, width in bytes), from the
/// library's [`SectionEntry::AT`]. The CRC is left out, as in [`HEADER_FIELDS`].
pub const ENTRY_FIELDS: [(&str, usize, usize); 6] = {
    let e = SectionEntry::AT;
    [
        at(e.kind),
        at(e.flags),
        at(e.offset),
        at(e.length),
        at(e.count),
        at(e.stride),
    ]
};

/// Byte offset and width of the header field named `field` (see [`HEADER_FIELDS`]).
pub fn header_field(field: &str) -> (usize, usize) {
    let (_, at, width) = HEADER_FIELDS
        .iter()
        .find(|(name, _, _)| *name == field)
        .copied()
        .expect("a header field");
    (at, width)
}

/// Reads a little-endian unsigned integer of `width` bytes at `at`.
pub fn read_uint(bytes: &[u8], at: usize, width: usize) -> u64 {
    let mut v = [0u8; 8];
    v[..width].copy_from_slice(&bytes[at..at + width]);
    u64::from_le_bytes(v)
}

/// Writes the low `width` bytes of `value`, little-endian, at `at`.
pub fn write_uint(bytes: &mut [u8], at: usize, width: usize, value: u64) {
    bytes[at..at + width].copy_from_slice(&value.to_le_bytes()[..width]);
}

/// Values at the edges of a field of `width` bytes, plus ones near `file_len` (for offsets
/// and lengths), each truncated to the field.
pub fn extreme_values(width: usize, file_len: u64) -> Vec<u64> {
    let max = if width == 8 {
        u64::MAX
    } else {
        (1u64 << (8 * width)) - 1
    };
    let mut values = vec![
        0,
        1,
        2,
        3,
        4,
        7,
        8,
        63,
        64,
        65,
        128,
        255,
        max / 2,
        max / 2 + 1,
        max - 63,
        max - 1,
        max,
        file_len - 64,
        file_len - 1,
        file_len,
        file_len + 1,
        file_len + 64,
        u64::from(u32::MAX),
        u64::from(u32::MAX) + 1,
        u64::MAX / 12 + 1,
        u64::MAX / 64 + 1,
    ];
    for v in &mut values {
        *v &= max;
    }
    values.sort_unstable();
    values.dedup();
    values
}

/// Byte offset of directory entry `index`.
pub fn entry_offset(index: usize) -> usize {
    HEADER_SIZE + ENTRY_SIZE * index
}

/// Byte offset and width of the field named `field` (see [`ENTRY_FIELDS`]) of directory
/// entry `index`.
pub fn entry_field(index: usize, field: &str) -> (usize, usize) {
    let (_, at, width) = ENTRY_FIELDS
        .iter()
        .find(|(name, _, _)| *name == field)
        .copied()
        .expect("a directory entry field");
    (entry_offset(index) + at, width)
}

/// Where an image was stopped, or that it answered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    /// `open` accepted the header and directory.
    pub opened: bool,
    /// Queries on the unverified file that returned an answer (of 6).
    pub answered: u32,
    /// Queries on the unverified file that returned an error (of 6).
    pub refused: u32,
    /// `verify` accepted the file.
    pub verified: bool,
}

/// Tallies of many outcomes, for the closing report of a suite.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    /// Images tried.
    pub tried: u64,
    /// Refused by `open`.
    pub refused_by_open: u64,
    /// Opened, then refused by `verify`.
    pub refused_by_verify: u64,
    /// Opened and verified (their answers were checked against brute force when asked).
    pub accepted: u64,
    /// Queries on opened, unverified images that answered.
    pub queries_answered: u64,
    /// Queries on opened, unverified images that returned an error.
    pub queries_refused: u64,
}

impl Tally {
    /// Counts one outcome.
    pub fn add(&mut self, o: Outcome) {
        self.tried += 1;
        match (o.opened, o.verified) {
            (false, _) => self.refused_by_open += 1,
            (true, false) => self.refused_by_verify += 1,
            (true, true) => self.accepted += 1,
        }
        self.queries_answered += u64::from(o.answered);
        self.queries_refused += u64::from(o.refused);
    }

    /// Sums two tallies.
    pub fn merge(mut self, other: Tally) -> Tally {
        self.tried += other.tried;
        self.refused_by_open += other.refused_by_open;
        self.refused_by_verify += other.refused_by_verify;
        self.accepted += other.accepted;
        self.queries_answered += other.queries_answered;
        self.queries_refused += other.queries_refused;
        self
    }
}

/// The poses of B in the queries of [`exercise`], for models of a given size: A stays at
/// the identity. Chosen so that every query has work to do on an intact file, but not so
/// much that a large sample takes long.
#[derive(Clone, Debug)]
pub struct Poses {
    /// Collision: rotated, shifted by 0.9 sizes along x (a shallow overlap).
    pub collide: Pose,
    /// Distance and tolerance: shifted by 1.05 sizes along x (a gap of a few percent).
    pub distance: Pose,
    /// Span: rotated and shifted by 0.15 sizes.
    pub span: Pose,
    /// Tolerance of the "closer than t" query: a tenth of the size.
    pub tolerance: f64,
}

impl Poses {
    /// Poses for models whose largest extent is `size` model units.
    pub fn for_size(size: f64) -> Poses {
        let r = *nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.5).matrix();
        let pose = |x: f64| Pose::new(r, nalgebra::Vector3::new(x, -0.05 * size, 0.1 * size));
        Poses {
            collide: pose(0.9 * size).expect("a rotation"),
            distance: Pose::translation(1.05 * size, 0.0, 0.0),
            span: pose(0.15 * size).expect("a rotation"),
            tolerance: 0.1 * size,
        }
    }

    /// Poses for the models of `file`, sized from its header bounds.
    pub fn for_file(file: &ObbtFile) -> Poses {
        let info = file.info();
        let size = (0..3)
            .map(|k| info.stats.bounds_max[k] - info.stats.bounds_min[k])
            .fold(0.0, f64::max);
        Poses::for_size(size)
    }
}

/// Opens `bytes`, runs every query kind on the unverified file (against itself and against
/// `partner`), then verifies it. With `check_answers`, a file that verifies must give the
/// brute-force collision answer over its own triangles. Any panic is a failure of the
/// caller's test.
pub fn exercise(bytes: &[u8], partner: &ObbtFile, poses: &Poses, check_answers: bool) -> Outcome {
    let mut outcome = Outcome::default();
    let Ok(file) = ObbtFile::from_aligned(AlignedBytes::copy_from(bytes)) else {
        return outcome;
    };
    outcome.opened = true;
    let _ = file.info();
    let id = Pose::identity();
    let mut count = |ok: bool| {
        if ok {
            outcome.answered += 1;
        } else {
            outcome.refused += 1;
        }
    };
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let all = CollideOptions::default();
    let (d, rule) = (DistanceOptions::default(), DescentRule::default());
    // A file whose sections cannot be viewed is refused by every query (when its pair is
    // made).
    let mut itself = PairQuery::new(&file, &file);
    let mut with_partner = PairQuery::new(&file, partner);
    let mut partner_first = PairQuery::new(partner, &file);
    count(answers(&mut itself, |p| {
        p.collide(&id, &poses.collide, &all)
    }));
    count(answers(&mut with_partner, |p| {
        p.collide(&id, &poses.span, &first)
    }));
    count(answers(&mut itself, |p| {
        p.distance(&id, &poses.distance, &d)
    }));
    count(answers(&mut partner_first, |p| {
        p.distance(&id, &poses.collide, &d)
    }));
    let t = ToleranceOptions {
        tolerance: poses.tolerance,
        rule,
    };
    count(answers(&mut itself, |p| p.within(&id, &poses.distance, &t)));
    count(answers(&mut itself, |p| {
        p.span(&id, &poses.span, &SpanOptions { rule })
    }));
    outcome.verified = file.verify().is_ok();
    if outcome.verified && check_answers {
        let got = itself
            .and_then(|mut p| p.collide(&id, &poses.collide, &all))
            .expect("a verified file answers");
        let expected = brute_force_pairs(&file, &id, &file, &poses.collide);
        assert_eq!(
            got.pairs, expected,
            "a damaged file that verifies must still answer exactly for what it stores"
        );
    }
    outcome
}

/// Whether `query` answers on `pair` (a pair that could not be made answers nothing).
fn answers<T>(
    pair: &mut Result<PairQuery<'_>, QueryError>,
    query: impl FnOnce(&mut PairQuery<'_>) -> Result<T, QueryError>,
) -> bool {
    pair.as_mut().is_ok_and(|p| query(p).is_ok())
}

/// Every contacting pair of two posed files by the brute-force oracle over the files' own
/// triangles, B mapped into A's frame exactly as the queries map it; sorted input-mesh ids.
pub fn brute_force_pairs(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
) -> Vec<(u32, u32)> {
    let split = |file: &ObbtFile| -> (Vec<u32>, Vec<Triangle>) {
        super::file_triangles(file)
            .into_iter()
            .map(|(id, t)| (id, t.map(nalgebra::Vector3::from)))
            .unzip()
    };
    let ((ids_a, ta), (ids_b, tb)) = (split(a), split(b));
    let tb = super::oracle::in_frame_of_a(pose_a, pose_b, &tb);
    let mut pairs: Vec<(u32, u32)> = super::oracle::contact_pairs(&ta, &tb)
        .into_iter()
        .map(|(i, j)| (ids_a[i as usize], ids_b[j as usize]))
        .collect();
    pairs.sort_unstable();
    pairs
}
