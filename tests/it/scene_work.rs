//! The scheduler skips what it can, counted: a scene built so that every counter of the
//! summary has one right value. A regression to "compute everything" (no culling, no
//! reuse, no early exit, no warm start) changes them and fails here.

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::query::Pose;
use obbtree::scene::{Answer, Effect, EventKind, Frame, SceneBuilder};
use std::sync::Arc;

/// Four unit cubes: `a` at the origin and `b` overlapping it (static), `c` at x = 5
/// (static), and `d` coming down along y towards `c`, one unit per frame, from y = 10 to
/// y = 1 (touching `c`).
///
/// Rules: everything `contact`; `a`–`c` a distance limited to 1 (always beyond: never
/// listed); `a`–`d` a distance without limit (every frame); `c`–`d` a clearance of 0.5;
/// `b`–`c` none.
#[test]
fn counters_of_a_scene_built_for_them() {
    let cube = Arc::new(build(&common::cube(0.5), &BuildOptions::default(), None).unwrap());
    let mut builder = SceneBuilder::new();
    let a = builder.object("a", cube.clone(), &[], Pose::identity());
    let b = builder.object("b", cube.clone(), &[], Pose::translation(0.9, 0.0, 0.0));
    let c = builder.object("c", cube.clone(), &[], Pose::translation(5.0, 0.0, 0.0));
    let d = builder.object("d", cube, &[], Pose::translation(5.0, 10.0, 0.0));
    builder.rule("*", "*", Effect::Contact);
    let limited = Effect::Distance {
        rel_err: 0.0,
        max_distance: Some(1.0),
    };
    builder.rule("a", "c", limited);
    let unlimited = Effect::Distance {
        rel_err: 0.0,
        max_distance: None,
    };
    builder.rule("d", "a", unlimited);
    builder.rule("c", "d", Effect::Clearance { clearance: 0.5 });
    builder.rule("b", "c", Effect::None);
    let mut naive = builder.clone().build().unwrap();
    naive.set_naive(true);
    let mut scene = builder.build().unwrap();
    for k in 0..10 {
        let mut frame = Frame::new();
        frame.set(d, Pose::translation(5.0, 10.0 - f64::from(k), 0.0));
        let report = scene.step(&frame).unwrap().clone();
        let reference = naive.step(&frame).unwrap();
        assert_eq!(
            report.disagreement(reference, |x, y| scene.effect(x, y)),
            None
        );
        let listed: Vec<(usize, usize)> = report.pairs.iter().map(|p| (p.a, p.b)).collect();
        let events: Vec<_> = report.events.iter().map(|e| (e.a, e.b, e.kind)).collect();
        match k {
            0 => {
                assert_eq!(listed, [(a, b), (a, d)]);
                assert_eq!(events, [(a, b, EventKind::ContactStarted)]);
                assert!(matches!(report.pairs[1].answer, Answer::Distance { .. }));
            }
            9 => {
                assert_eq!(listed, [(a, b), (a, d), (c, d)]);
                assert_eq!(events, [(c, d, EventKind::ClearanceViolated)]);
            }
            _ => {
                assert_eq!(listed, [(a, b), (a, d)], "frame {k}");
                assert!(events.is_empty(), "frame {k}");
            }
        }
    }
    let s = scene.summary();
    assert_eq!((s.frames, s.objects, s.pairs_with_effect), (10, 4, 5));
    // Broad-phase pairs a-b, a-c, b-d, c-d: a-c, b-d and c-d culled on frames 0-8, a-c and
    // b-d on frame 9.
    assert_eq!(s.culled, 3 * 9 + 2);
    // a-b (static) answered on frame 0, reused on the 9 others.
    assert_eq!(s.reused, 9);
    let queries = s.narrow.by_effect().map(|(name, w)| (name, w.queries));
    assert_eq!(
        queries,
        [
            ("contact", 1),
            ("contacts", 0),
            ("clearance", 1),
            ("distance", 10),
            ("span", 0)
        ]
    );
    // The first contact of a-b and the violated clearance of c-d stopped early.
    assert_eq!(s.early_exits, 2);
    // a-d: warm-started from frame 1 on.
    assert_eq!(s.warm_starts, 9);
    // The reference runs all five pairs every frame.
    assert_eq!(naive.summary().narrow.total().queries, 50);
    assert_eq!((naive.summary().culled, naive.summary().reused), (0, 0));
}

/// Each effect runs its query with the rule's options, counted by the same work as a
/// direct query: first contact (not all pairs) for `contact`; for `distance`, the rule's
/// relative error and maximum, and from the second frame the previous answer as a warm
/// start. Two cows overlap (`a`–`b`, contact); `c`–`d` are apart (relative error 0.3), and
/// so are `e`–`f`, with a maximum of half their distance (their boxes overlap, so the
/// broad phase keeps them).
#[test]
fn each_effect_runs_its_query_with_the_rules_options() {
    use obbtree::query::{CollideOptions, DistanceOptions, PairQuery};
    let cow = Arc::new(build(&common::cow(), &BuildOptions::default(), None).unwrap());
    let poses = [
        (0.0, 3),
        (0.3, 4),
        (10.0, 1),
        (11.6, 2),
        (20.0, 5),
        (20.85, 6),
    ]
    .map(|(x, seed)| common::sliding_pose(x, seed));

    // The queries the rules ask for, run directly.
    let mut pair = PairQuery::new(&cow, &cow).unwrap();
    let first = CollideOptions {
        first_contact: true,
        ..Default::default()
    };
    let contact = pair.collide(&poses[0], &poses[1], &first).unwrap();
    let all = pair
        .collide(&poses[0], &poses[1], &Default::default())
        .unwrap();
    assert!(contact.colliding);
    assert!(contact.work.bv_tests() < all.work.bv_tests());
    let with = |rel_err, max_distance, warm_start| DistanceOptions {
        rel_err,
        max_distance,
        warm_start,
        ..Default::default()
    };
    let mut distance = |(i, j): (usize, usize), options: &DistanceOptions| {
        pair.distance(&poses[i], &poses[j], options).unwrap()
    };
    let rel_err = 0.3;
    let cd = distance((2, 3), &with(rel_err, f64::INFINITY, None));
    let cd_exact = distance((2, 3), &DistanceOptions::default());
    assert_ne!(cd.work.bv_tests(), cd_exact.work.bv_tests());
    let ef_unlimited = distance((4, 5), &DistanceOptions::default());
    let limit = ef_unlimited.closest.expect("e–f measured").distance / 2.0;
    let ef = distance((4, 5), &with(0.0, limit, None));
    assert!(ef.closest.is_none() && limit > 0.0);
    assert_ne!(ef.work.bv_tests(), ef_unlimited.work.bv_tests());

    let mut builder = SceneBuilder::new();
    let names = ["a", "b", "c", "d", "e", "f"];
    let ids: Vec<_> = (names.iter().zip(&poses))
        .map(|(name, pose)| builder.object(name, cow.clone(), &[], *pose))
        .collect();
    builder.rule("*", "*", Effect::None);
    builder.rule("a", "b", Effect::Contact);
    let relative = Effect::Distance {
        rel_err,
        max_distance: None,
    };
    builder.rule("c", "d", relative);
    let limited = Effect::Distance {
        rel_err: 0.0,
        max_distance: Some(limit),
    };
    builder.rule("e", "f", limited);
    let mut scene = builder.build().unwrap();
    let listed = scene.step(&Frame::new()).unwrap().pairs.len();
    assert_eq!(listed, 2, "a–b and c–d listed");
    let narrow = scene.summary().narrow;
    assert_eq!((narrow.contact.queries, narrow.distance.queries), (1, 2));
    assert_eq!(narrow.contact.box_tests, contact.work.bv_tests());
    assert_eq!(
        narrow.distance.box_tests,
        cd.work.bv_tests() + ef.work.bv_tests()
    );
    assert_eq!(narrow.contact.triangle_tests, contact.work.tri_tests());
    assert_eq!(
        narrow.distance.triangle_tests,
        cd.work.tri_tests() + ef.work.tri_tests()
    );

    // d moves a little: c–d starts from frame 0's answer.
    let moved = common::sliding_pose(11.62, 2);
    let warm = pair
        .distance(
            &poses[2],
            &moved,
            &with(rel_err, f64::INFINITY, cd.warm_start),
        )
        .unwrap();
    let cold = pair
        .distance(&poses[2], &moved, &with(rel_err, f64::INFINITY, None))
        .unwrap();
    assert_ne!(warm.work.bv_tests(), cold.work.bv_tests());
    let mut frame = Frame::new();
    frame.set(ids[3], moved);
    scene.step(&frame).unwrap();
    let after = scene.summary().narrow;
    assert_eq!(
        after.distance.box_tests - narrow.distance.box_tests,
        warm.work.bv_tests()
    );
}
