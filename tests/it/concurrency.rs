//! Many threads query one mapped file: 8 threads x 1,000 mixed queries, each answer equal to
//! the single-threaded one.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used)]

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::query::{CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, SpanOptions};

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
