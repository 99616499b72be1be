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
