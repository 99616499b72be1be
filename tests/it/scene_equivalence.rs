//! The fast scheduler answers every frame as the naive reference does: random scenes of
//! 2 to 30 objects from small generated meshes, random rules of every effect, 20 to 200
//! frames of coherent and incoherent motion with some objects static, every volume type
//! and precision. Pairs and events must agree (witnesses aside; distances to 1e-9, or
//! within a rule's `rel_err`), checked by `FrameReport::disagreement`.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::indexing_slicing,
    clippy::unwrap_in_result
)]

use crate::common;

use nalgebra::{Rotation3, Unit, Vector3};
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::format::ObbtFile;
use obbtree::query::Pose;
use obbtree::real::Precision;
use obbtree::scene::{Effect, Frame, SceneBuilder};
use proptest::prelude::*;
use std::sync::{Arc, OnceLock};

/// Four small meshes, built once in every volume type and precision: `[kind][mesh]`.
fn assets() -> &'static Vec<Vec<Arc<ObbtFile>>> {
    static ASSETS: OnceLock<Vec<Vec<Arc<ObbtFile>>>> = OnceLock::new();
    ASSETS.get_or_init(|| {
        let meshes = [
            common::uv_sphere(0.5, 4, 6),
            common::cube(0.3),
            common::cuboid([0.6, 0.1, 0.2], [0.1, 0.0, 0.0]),
            common::grid(2),
        ];
        let mut out = Vec::new();
        for bv in BvKind::ALL {
            for precision in Precision::ALL {
                let options = BuildOptions {
                    bv,
                    precision,
                    ..BuildOptions::default()
                };
                out.push(
                    meshes
                        .iter()
                        .map(|m| Arc::new(build(m, &options, None).unwrap()))
                        .collect(),
                );
            }
        }
        out
    })
}

#[derive(Clone, Debug)]
enum Motion {
    Static,
    /// Drifts and turns a little each frame.
    Coherent {
        velocity: [f64; 3],
        spin: [f64; 3],
    },
    /// Jumps to a new random pose every frame it moves.
    Incoherent,
}

#[derive(Clone, Debug)]
struct ObjectCase {
    mesh: usize,
    group: usize,
    start: [f64; 6],
    motion: Motion,
}

#[derive(Clone, Debug)]
struct RuleCase {
    a: usize,
    b: usize,
    effect: Effect,
}

fn effect_strategy() -> impl Strategy<Value = Effect> {
    prop_oneof![
        Just(Effect::None),
        Just(Effect::Contact),
        Just(Effect::Contacts),
        (0.02..0.6f64).prop_map(|clearance| Effect::Clearance { clearance }),
        (
            prop_oneof![Just(0.0), 0.01..0.3f64],
            prop_oneof![Just(None), (0.05..2.0f64).prop_map(Some)]
        )
            .prop_map(|(rel_err, max_distance)| Effect::Distance {
                rel_err,
                max_distance
            }),
        Just(Effect::Span),
    ]
}

fn object_strategy() -> impl Strategy<Value = ObjectCase> {
    let motion = prop_oneof![
        Just(Motion::Static),
        (
            prop::array::uniform3(-0.05..0.05f64),
            prop::array::uniform3(-0.1..0.1f64)
        )
            .prop_map(|(velocity, spin)| Motion::Coherent { velocity, spin }),
        Just(Motion::Incoherent),
    ];
    (
        0..4usize,
        0..3usize,
        prop::array::uniform6(-1.0..1.0f64),
        motion,
    )
        .prop_map(|(mesh, group, start, motion)| ObjectCase {
            mesh,
            group,
            start,
            motion,
        })
}

/// A pose from three coordinates in [-1.5, 1.5] and three rotation angles.
fn pose(p: &[f64; 6]) -> Pose {
    let r = Rotation3::from_euler_angles(p[3] * 3.0, p[4] * 3.0, p[5] * 3.0);
    Pose::new(*r.matrix(), Vector3::new(p[0], p[1], p[2]) * 1.5).unwrap()
}

fn run_case(
    kind: usize,
    objects: &[ObjectCase],
    rules: &[RuleCase],
    frames: usize,
    seed: u64,
) -> Result<(), TestCaseError> {
    let assets = &assets()[kind];
    let mut builder = SceneBuilder::new();
    let names: Vec<String> = (0..objects.len()).map(|k| format!("o{k}")).collect();
    for (k, o) in objects.iter().enumerate() {
        let group = format!("g{}", o.group);
        builder.object(&names[k], assets[o.mesh].clone(), &[&group], pose(&o.start));
    }
    let side = |s: usize| match s % 5 {
        0 => "*".to_string(),
        1 | 2 => format!("g{}", objects[s % objects.len()].group),
        _ => names[s % names.len()].clone(),
    };
    for r in rules {
        builder.rule(&side(r.a), &side(r.b), r.effect);
    }
    let mut fast = builder.clone().build().unwrap();
    let mut naive = builder.build().unwrap();
    naive.set_naive(true);
    let mut poses: Vec<Pose> = objects.iter().map(|o| pose(&o.start)).collect();
    let mut random = common::rng::Rng::new(seed);
    for f in 0..frames {
        let mut frame = Frame::new();
        for (k, o) in objects.iter().enumerate() {
            let moved = match &o.motion {
                Motion::Static => continue,
                Motion::Coherent { velocity, spin } => {
                    let turn = Rotation3::from_axis_angle(
                        &Unit::new_normalize(Vector3::new(spin[0], spin[1], spin[2] + 1e-3)),
                        0.2,
                    );
                    let r = turn.matrix() * poses[k].rotation();
                    let t = poses[k].translation_vector() + Vector3::from(*velocity);
                    Pose::new(r, t).unwrap()
                }
                // Some frames it stays, so reuse is exercised too.
                Motion::Incoherent if f % 3 == 1 => continue,
                Motion::Incoherent => {
                    let p: [f64; 6] = std::array::from_fn(|_| random.signed());
                    pose(&p)
                }
            };
            poses[k] = moved;
            frame.set(k, moved);
        }
        let got = fast.step(&frame).unwrap().clone();
        let want = naive.step(&frame).unwrap();
        if let Some(d) = got.disagreement(want, |a, b| fast.effect(a, b)) {
            return Err(TestCaseError::fail(d));
        }
    }
    // The fast path did less: never more narrow queries than the reference.
    prop_assert!(fast.summary().narrow.total().queries <= naive.summary().narrow.total().queries);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn fast_scenes_answer_as_the_naive_reference(
        kind in 0..6usize,
        objects in prop::collection::vec(object_strategy(), 2..=30),
        rules in prop::collection::vec((0..40usize, 0..40usize, effect_strategy()), 1..8),
        frames in 20..200usize,
        seed in any::<u64>(),
    ) {
        let rules: Vec<RuleCase> = rules.into_iter().map(|(a, b, effect)| RuleCase { a, b, effect }).collect();
        // Keep a case's naive work bounded: many objects, fewer frames.
        let frames = frames.min(4000 / objects.len());
        run_case(kind, &objects, &rules, frames, seed)?;
    }
}
