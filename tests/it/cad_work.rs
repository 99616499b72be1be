//! The work of queries between CAD parts of long thin triangles, pinned: ALSTOM_TEST4
//! against itself and against anchor (`tests/fixtures/cad`, from CGAL's data meshes,
//! normalised to unit bounding spheres), at the 24 poses of `obbtree poses random --count
//! 24 --radius 1.6 --seed 7`, the peers benchmark's CAD poses. Slivers are where box tests
//! cost most and prune least, so a change to the fit, the split or the box tests shows
//! here first; a deliberate improvement updates the counts, with the before and after in
//! its commit message.
// Test code outside `#[test]` functions (helpers): a failure is a failed test.
#![allow(clippy::expect_used)]

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose, Work};

fn part(name: &str) -> ObbtFile {
    part_with(name, &BuildOptions::default())
}

fn part_with(name: &str, options: &BuildOptions) -> ObbtFile {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/cad")
        .join(name);
    let mesh = TriMesh::load(&path).expect("the fixture loads");
    build(&mesh, options, None).expect("builds")
}

/// Node pairs and triangle pairs of a sum of work.
fn pairs(work: &[Work]) -> (u64, u64) {
    let nodes = work.iter().map(|w| w.nodes_visited).sum();
    let triangles = work.iter().map(|w| w.tri_contact + w.tri_separated).sum();
    (nodes, triangles)
}

/// Per pair of parts: contacts, then (node pairs, triangle pairs) of all-pairs collision,
/// first contact, exact distance and distance within 1%.
type Pinned = (usize, (u64, u64), (u64, u64), (u64, u64), (u64, u64));

fn run(a: &ObbtFile, b: &ObbtFile) -> Pinned {
    let poses: Vec<(Pose, Pose)> = obbtree::generate::random_poses(24, 1.6, 7)
        .expect("poses")
        .into_iter()
        .map(|[a, b]| (a, b))
        .collect();
    let mut pair = PairQuery::new(a, b).expect("one volume type");
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let rel = DistanceOptions {
        rel_err: 0.01,
        ..DistanceOptions::default()
    };
    let (mut contacts, mut all, mut firsts, mut exact, mut within) =
        (0, Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, (pa, pb)) in poses.iter().enumerate() {
        let c = pair
            .collide(pa, pb, &CollideOptions::default())
            .expect("all");
        let f = pair.collide(pa, pb, &first).expect("first");
        let e = pair
            .distance(pa, pb, &DistanceOptions::default())
            .expect("exact");
        let r = pair.distance(pa, pb, &rel).expect("rel_err");
        // The answers agree with each other before their work is counted.
        assert_eq!(c.colliding, f.colliding, "pose {k}: first contact");
        assert_eq!(
            c.colliding,
            e.distance() == 0.0,
            "pose {k}: distance 0 iff touching"
        );
        assert!(
            r.distance() >= e.distance() && r.distance() <= 1.01 * e.distance(),
            "pose {k}: {} against {}",
            r.distance(),
            e.distance()
        );
        contacts += c.pairs.len();
        all.push(c.work);
        firsts.push(f.work);
        exact.push(e.work);
        within.push(r.work);
    }
    (
        contacts,
        pairs(&all),
        pairs(&firsts),
        pairs(&exact),
        pairs(&within),
    )
}

#[test]
fn cad_work_is_pinned() {
    let (alstom, anchor) = (part("ALSTOM_TEST4.obj"), part("anchor.obj"));
    let same = run(&alstom, &alstom);
    let mixed = run(&alstom, &anchor);
    assert_eq!(
        same,
        (180, (2_816, 336), (171, 4), (12_044, 970), (7_392, 219)),
        "ALSTOM_TEST4 against itself"
    );
    assert_eq!(
        mixed,
        (
            694,
            (10_602, 1_336),
            (536, 7),
            (22_142, 2_607),
            (16_820, 1_737)
        ),
        "ALSTOM_TEST4 against anchor"
    );
}

/// Splitting along the axis of least child volume is what takes the anchor's work down:
/// against the same part split along the greatest spread only, every query kind visits
/// at most 0.6 of the node pairs (measured: a quarter to a half).
#[test]
fn splitting_by_volume_cuts_the_anchors_work() {
    let spread_only = BuildOptions {
        split_by_volume: false,
        ..BuildOptions::default()
    };
    let (by_volume, by_spread) = (part("anchor.obj"), part_with("anchor.obj", &spread_only));
    by_spread.verify().expect("verifies");
    let (on, off) = (run(&by_volume, &by_volume), run(&by_spread, &by_spread));
    assert_eq!(on.0, off.0, "the same contacts");
    for (kind, (a, b)) in [
        ("all pairs", (on.1, off.1)),
        ("first contact", (on.2, off.2)),
        ("exact distance", (on.3, off.3)),
        ("distance within 1%", (on.4, off.4)),
    ] {
        assert!(
            a.0 * 10 <= b.0 * 6,
            "{kind}: {} node pairs split by volume, {} by spread",
            a.0,
            b.0
        );
    }
}
