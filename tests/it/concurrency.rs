//! Many threads query one mapped file: 8 threads x 1,000 mixed queries, each answer equal to
//! the single-threaded one; and `query::batch`, against one-at-a-time calls.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used)]

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::query::{
    batch, BatchError, BatchOptions, CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose,
    PoseBatch, QueryError, SpanOptions,
};
use std::num::NonZeroUsize;

/// One query's answer, reduced to comparable numbers.
#[derive(Debug, PartialEq)]
enum Answer {
    Pairs(Vec<(u32, u32)>),
    Distance(f64, u32, u32),
    Span(f64),
}

/// Query `k` of the file against itself (`pair`).
fn query(k: usize, pair: &mut PairQuery<'_>) -> Answer {
    let pose = common::sliding_pose(0.05 * (k % 40) as f64, k as u64);
    let a = Pose::identity();
    match k % 3 {
        0 => Answer::Pairs(
            pair.collide(&a, &pose, &CollideOptions::default())
                .unwrap()
                .pairs,
        ),
        1 => {
            let d = pair
                .distance(&a, &pose, &DistanceOptions::default())
                .unwrap()
                .closest
                .unwrap();
            Answer::Distance(d.distance, d.tri_a, d.tri_b)
        }
        _ => {
            let options = SpanOptions {
                rule: DescentRule::default(),
            };
            Answer::Span(pair.span(&a, &pose, &options).unwrap().span())
        }
    }
}

#[test]
fn eight_threads_agree_with_one() {
    let dir = std::env::temp_dir().join(format!("obbtree-concurrency-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sphere.obbt");
    build(
        &common::uv_sphere(0.5, 12, 20),
        &BuildOptions::default(),
        None,
    )
    .unwrap()
    .write_atomic(&path)
    .unwrap();
    let file = ObbtFile::open(&path).unwrap();
    const PER_THREAD: usize = 1000;
    let mut pair = PairQuery::new(&file, &file).unwrap();
    let expected: Vec<Answer> = (0..PER_THREAD).map(|k| query(k, &mut pair)).collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..8)
            .map(|t| {
                let (file, expected) = (&file, &expected);
                scope.spawn(move || {
                    let mut pair = PairQuery::new(file, file).unwrap();
                    // Each thread walks the queries in its own order.
                    for i in 0..PER_THREAD {
                        let k = (i * 7 + t * 131) % PER_THREAD;
                        assert_eq!(query(k, &mut pair), expected[k], "thread {t}, query {k}");
                    }
                })
            })
            .collect();
        for h in handles {
            h.join().unwrap();
        }
    });
    std::fs::remove_dir_all(dir).unwrap();
}

/// `query::batch` over the cow: every answer equals the one-at-a-time call on the same
/// poses, whatever the thread count and with A's single pose broadcast.
#[test]
fn batches_equal_one_at_a_time_calls() {
    let cow = build(&common::cow(), &BuildOptions::default(), None).unwrap();
    let poses_b: Vec<Pose> = (0..200)
        .map(|k| common::turned_pose(k, 0.05 * (k % 10) as f64))
        .collect();
    let here = [Pose::identity()];
    let poses_a = vec![Pose::identity(); poses_b.len()];
    let mut pair = PairQuery::new(&cow, &cow).unwrap();
    let collide = CollideOptions::default();
    let expected: Vec<(Vec<(u32, u32)>, f64)> = poses_b
        .iter()
        .map(|pose| {
            let pairs = pair.collide(&here[0], pose, &collide).unwrap().pairs;
            let distance = pair
                .distance(&here[0], pose, &DistanceOptions::default())
                .unwrap()
                .distance();
            (pairs, distance)
        })
        .collect();
    assert!(expected.iter().any(|(pairs, _)| pairs.is_empty()));
    assert!(expected.iter().any(|(pairs, _)| !pairs.is_empty()));
    for side_a in [&here[..], &poses_a[..]] {
        for threads in [None, NonZeroUsize::new(1), NonZeroUsize::new(3)] {
            let answers = batch(
                &cow,
                &cow,
                PoseBatch::new(side_a, &poses_b).unwrap(),
                &BatchOptions { threads },
                |pair, a, b| -> Result<_, QueryError> {
                    let pairs = pair.collide(a, b, &collide)?.pairs;
                    let distance = pair.distance(a, b, &DistanceOptions::default())?;
                    Ok((pairs, distance.distance()))
                },
            )
            .unwrap();
            let answers: Vec<_> = answers.into_iter().map(Result::unwrap).collect();
            assert_eq!(
                answers,
                expected,
                "{threads:?} threads, {} A poses",
                side_a.len()
            );
        }
    }
}

/// Where a batch's queries run: a single pose or one thread on the calling thread (no
/// hand-off to a pool), `Some(n)` threads on a kept pool of exactly `n`, never the caller.
#[test]
fn batches_run_where_their_thread_count_says() {
    let cube = build(&common::cube(0.5), &BuildOptions::default(), None).unwrap();
    let poses: Vec<Pose> = (0..64).map(|k| common::turned_pose(k, 0.3)).collect();
    let caller = std::thread::current().id();
    // (thread, pool size) of every query of a batch.
    let run = |poses: &[Pose], threads: Option<usize>| -> Vec<(std::thread::ThreadId, usize)> {
        let options = BatchOptions {
            threads: threads.and_then(NonZeroUsize::new),
        };
        let both = PoseBatch::new(poses, poses).unwrap();
        batch(
            &cube,
            &cube,
            both,
            &options,
            |pair, a, b| -> Result<_, QueryError> {
                pair.collide(a, b, &CollideOptions::default())?;
                Ok((std::thread::current().id(), rayon::current_num_threads()))
            },
        )
        .unwrap()
        .into_iter()
        .map(Result::unwrap)
        .collect()
    };
    assert_eq!(run(&poses[..1], None)[0].0, caller, "a single pose");
    assert!(
        run(&poses, Some(1)).iter().all(|(t, _)| *t == caller),
        "one thread"
    );
    for n in [2, 3, 2] {
        let ran = run(&poses, Some(n));
        assert!(ran.iter().all(|(t, _)| *t != caller), "{n} threads");
        assert!(ran.iter().all(|(_, size)| *size == n), "{n} threads");
    }
}

/// What a batch refuses before any pose, and a query error as its pose's answer.
#[test]
fn batch_errors() {
    let poses: Vec<Pose> = (0..4).map(|k| common::turned_pose(k, 0.3)).collect();
    assert!(matches!(
        PoseBatch::new(&poses[..2], &poses[..3]),
        Err(BatchError::Lengths { a: 2, b: 3 })
    ));
    assert_eq!(PoseBatch::new(&poses[..1], &[]).unwrap().len(), 0);
    let mesh = common::cube(0.5);
    let obb = build(&mesh, &BuildOptions::default(), None).unwrap();
    let aabb_options = BuildOptions {
        bv: obbtree::bv::BvKind::Aabb,
        ..BuildOptions::default()
    };
    let aabb = build(&mesh, &aabb_options, None).unwrap();
    let both = PoseBatch::new(&poses, &poses).unwrap();
    let collide = |pair: &mut PairQuery<'_>, a: &Pose, b: &Pose| {
        pair.collide(a, b, &CollideOptions::default())
    };
    // Checked once, for an empty batch too.
    let none = PoseBatch::new(&[], &[]).unwrap();
    for poses in [both, none] {
        let refused = batch(&obb, &aabb, poses, &BatchOptions::default(), collide);
        assert!(matches!(
            refused,
            Err(BatchError::Pair(QueryError::MismatchedTrees { .. }))
        ));
    }
    let negative = DistanceOptions {
        rel_err: -1.0,
        ..DistanceOptions::default()
    };
    let answers = batch(&obb, &obb, both, &BatchOptions::default(), |pair, a, b| {
        pair.distance(a, b, &negative)
    })
    .unwrap();
    assert_eq!(answers.len(), 4);
    assert!(answers.iter().all(|a| matches!(
        a,
        Err(QueryError::BadOption {
            name: "rel_err",
            ..
        })
    )));
}
