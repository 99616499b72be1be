//! The narrow phase: the query that answers a pair's effect, run for each pair the
//! scheduler could not answer without one.

use super::object::SceneObject;
use super::report::Answer;
use super::rules::Effect;
use crate::query::{
    collide, distance, distance_below, span, with_views, within_tolerance, CollideOptions,
    DescentRule, DistanceOptions, QueryContext, QueryError, Side, Stats, Witness,
};
use rayon::prelude::*;
use std::time::Instant;

/// A narrow query to run.
#[derive(Clone, Copy, Debug)]
pub(super) struct Job {
    /// The pair, lower id first.
    pub(super) pair: (u32, u32),
    /// What it asks for.
    pub(super) effect: Effect,
    /// The previous distance answer's triangle pair, to start from.
    pub(super) warm: Option<Witness>,
}

/// A narrow query's result.
#[derive(Clone, Debug)]
pub(super) struct Outcome {
    /// The new answer; `None` is the empty one.
    pub(super) answer: Option<Answer>,
    /// A distance answer's triangle pair, to warm-start the next frame's query.
    pub(super) witness: Option<Witness>,
    /// The query's work.
    pub(super) stats: Stats,
    /// Whether the query stopped before its full traversal.
    pub(super) early_exit: bool,
    /// Time the query took.
    pub(super) seconds: f64,
}

/// Runs `jobs` in parallel (one query context per thread), each outcome timed, in the
/// order of `jobs`; `objects` are the scene's, at this frame's poses.
pub(super) fn run_jobs(
    jobs: &[Job],
    objects: &[SceneObject],
    naive: bool,
) -> Vec<Result<Outcome, QueryError>> {
    jobs.par_iter()
        .with_min_len(4)
        .map_init(QueryContext::new, |context, job| {
            let started = Instant::now();
            let mut outcome = run_job(job, objects, naive, context);
            if let Ok(o) = &mut outcome {
                o.seconds = started.elapsed().as_secs_f64();
            }
            outcome
        })
        .collect()
}

/// Runs one narrow query: the cheapest that answers the effect, or (naive) the full exact
/// one.
fn run_job(
    job: &Job,
    objects: &[SceneObject],
    naive: bool,
    context: &mut QueryContext,
) -> Result<Outcome, QueryError> {
    let missing = QueryError::CorruptTree {
        which: Side::A,
        what: "no such object",
    };
    let (Some(a), Some(b)) = (
        objects.get(job.pair.0 as usize),
        objects.get(job.pair.1 as usize),
    ) else {
        return Err(missing);
    };
    let (pa, pb) = (&a.pose, &b.pose);
    with_views!(&*a.asset, &*b.asset, |va, vb| {
        let rule = DescentRule::default();
        let outcome = |answer, witness, stats, early_exit| Outcome {
            answer,
            witness,
            stats,
            early_exit,
            seconds: 0.0,
        };
        let exact = DistanceOptions::default();
        Ok(match (job.effect, naive) {
            (Effect::None, _) => outcome(None, None, Stats::default(), false),
            (Effect::Contact, false) => {
                let first = CollideOptions {
                    first_contact: true,
                    ..CollideOptions::default()
                };
                let r = collide(&va, pa, &vb, pb, &first, context)?;
                let answer = r.colliding.then_some(Answer::Contact);
                outcome(answer, None, r.stats, r.colliding)
            }
            (Effect::Contact | Effect::Contacts, _) => {
                let r = collide(&va, pa, &vb, pb, &CollideOptions::default(), context)?;
                let answer = match job.effect {
                    Effect::Contact => r.colliding.then_some(Answer::Contact),
                    _ => r.colliding.then_some(Answer::Contacts(r.pairs)),
                };
                outcome(answer, None, r.stats, false)
            }
            (Effect::Clearance { clearance }, false) => {
                let r = within_tolerance(&va, pa, &vb, pb, clearance, rule, context)?;
                let answer = r.witness.map(|w| Answer::Closer {
                    tri_a: w.tri_a,
                    tri_b: w.tri_b,
                    distance: w.distance,
                });
                outcome(answer, None, r.stats, r.closer)
            }
            (Effect::Clearance { clearance }, true) => {
                let r = distance(&va, pa, &vb, pb, &exact, context)?;
                let answer = (r.distance < clearance).then_some(Answer::Closer {
                    tri_a: r.tri_a,
                    tri_b: r.tri_b,
                    distance: r.distance,
                });
                outcome(answer, None, r.stats, false)
            }
            (
                Effect::Distance {
                    rel_err,
                    max_distance,
                },
                _,
            ) => {
                let options = if naive {
                    exact
                } else {
                    DistanceOptions {
                        rel_err,
                        warm_start: job.warm,
                        ..DistanceOptions::default()
                    }
                };
                let measured = |r: &crate::query::DistanceResult| Answer::Distance {
                    distance: r.distance,
                    tri_a: r.tri_a,
                    tri_b: r.tri_b,
                };
                match max_distance {
                    Some(limit) if !naive => {
                        let (r, stats) =
                            distance_below(&va, pa, &vb, pb, &options, limit, context)?;
                        let far = r.is_none();
                        let witness = r.as_ref().map(|r| r.witness);
                        let answer = r.as_ref().map_or(Answer::Beyond, measured);
                        outcome(Some(answer), witness, stats, far)
                    }
                    _ => {
                        let r = distance(&va, pa, &vb, pb, &options, context)?;
                        let far = max_distance.is_some_and(|limit| r.distance >= limit);
                        let answer = if far { Answer::Beyond } else { measured(&r) };
                        outcome(Some(answer), Some(r.witness), r.stats, false)
                    }
                }
            }
            (Effect::Span, _) => {
                let r = span(&va, pa, &vb, pb, rule, context)?;
                outcome(Some(Answer::Span(r.span)), None, r.stats, false)
            }
        })
    })
}
