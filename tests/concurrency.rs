//! Many threads query one mapped file: 8 threads x 1,000 mixed queries, each answer equal to
//! the single-threaded one.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used)]

mod common;

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::query::{
    collide_files, distance_files, span_files, CollideOptions, DescentRule, DistanceOptions, Pose,
    QueryContext,
};

/// One query's answer, reduced to comparable numbers.
#[derive(Debug, PartialEq)]
enum Answer {
    Pairs(Vec<(u32, u32)>),
    Distance(f64, u32, u32),
    Span(f64),
}

fn query(k: usize, file: &ObbtFile, context: &mut QueryContext) -> Answer {
    let pose = common::sliding_pose(0.05 * (k % 40) as f64, k as u64);
    let a = Pose::identity();
    match k % 3 {
        0 => Answer::Pairs(
            collide_files(file, &a, file, &pose, &CollideOptions::default(), context)
                .unwrap()
                .pairs,
        ),
        1 => {
            let d = distance_files(file, &a, file, &pose, &DistanceOptions::default(), context)
                .unwrap();
            Answer::Distance(d.distance, d.tri_a, d.tri_b)
        }
        _ => Answer::Span(
            span_files(file, &a, file, &pose, DescentRule::default(), context)
                .unwrap()
                .span,
        ),
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
    let mut context = QueryContext::new();
    let expected: Vec<Answer> = (0..PER_THREAD)
        .map(|k| query(k, &file, &mut context))
        .collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..8)
            .map(|t| {
                let (file, expected) = (&file, &expected);
                scope.spawn(move || {
                    let mut context = QueryContext::new();
                    // Each thread walks the queries in its own order.
                    for i in 0..PER_THREAD {
                        let k = (i * 7 + t * 131) % PER_THREAD;
                        assert_eq!(
                            query(k, file, &mut context),
                            expected[k],
                            "thread {t}, query {k}"
                        );
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
