//! The narrow phase: the query that answers a pair's effect, run for each pair the
//! scheduler could not answer without one.

use super::object::SceneObject;
use super::report::Answer;
use super::rules::Effect;
use crate::query::{
    CollideOptions, DistanceOptions, PairQuery, Pose, QueryContext, QueryError, Side, SpanOptions,
    ToleranceOptions, WarmStart, Work,
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
    pub(super) warm_start: Option<WarmStart>,
}

/// A narrow query's result.
#[derive(Clone, Debug)]
pub(super) struct Outcome {
    /// The new answer; `None` is the empty one.
    pub(super) answer: Option<Answer>,
    /// A distance answer's triangle pair, to warm-start the next frame's query.
    pub(super) warm_start: Option<WarmStart>,
    /// The query's work.
    pub(super) work: Work,
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
    let mut pair = PairQuery::with_context(&a.asset, &b.asset, std::mem::take(context))?;
    let outcome = narrow(&mut pair, pa, pb, job, naive);
    *context = pair.into_context();
    outcome
}

/// The query that answers `job`'s effect on `pair` at poses `pa`, `pb`: the cheapest that
/// answers it, or (naive) the full exact one.
fn narrow(
    pair: &mut PairQuery<'_>,
    pa: &Pose,
    pb: &Pose,
    job: &Job,
    naive: bool,
) -> Result<Outcome, QueryError> {
    let outcome = |answer, warm_start, work, early_exit| Outcome {
        answer,
        warm_start,
        work,
        early_exit,
        seconds: 0.0,
    };
    let exact = DistanceOptions::default();
    Ok(match (job.effect, naive) {
        (Effect::None, _) => outcome(None, None, Work::default(), false),
        (Effect::Contact, false) => {
            let first = CollideOptions {
                first_contact: true,
                ..CollideOptions::default()
            };
            let r = pair.collide(pa, pb, &first)?;
            let answer = r.colliding.then_some(Answer::Contact);
            outcome(answer, None, r.work, r.colliding)
        }
        (Effect::Contact | Effect::Contacts, _) => {
            let r = pair.collide(pa, pb, &CollideOptions::default())?;
            let answer = match job.effect {
                Effect::Contact => r.colliding.then_some(Answer::Contact),
                _ => r.colliding.then_some(Answer::Contacts(r.pairs)),
            };
            outcome(answer, None, r.work, false)
        }
        (Effect::Clearance { clearance }, false) => {
            let r = pair.within(pa, pb, &ToleranceOptions::new(clearance))?;
            let answer = r.witness.map(|w| Answer::Closer {
                tri_a: w.tri_a,
                tri_b: w.tri_b,
                distance: w.distance,
            });
            outcome(answer, None, r.work, r.closer())
        }
        (Effect::Clearance { clearance }, true) => {
            let r = pair.distance(pa, pb, &exact)?;
            let answer = r
                .closest
                .filter(|w| w.distance < clearance)
                .map(|w| Answer::Closer {
                    tri_a: w.tri_a,
                    tri_b: w.tri_b,
                    distance: w.distance,
                });
            outcome(answer, None, r.work, false)
        }
        (
            Effect::Distance {
                rel_err,
                max_distance,
            },
            _,
        ) => {
            // The naive run measures exactly and compares with the maximum afterwards.
            let options = if naive {
                exact
            } else {
                DistanceOptions {
                    rel_err,
                    max_distance: max_distance.unwrap_or(f64::INFINITY),
                    warm_start: job.warm_start,
                    ..DistanceOptions::default()
                }
            };
            let r = pair.distance(pa, pb, &options)?;
            let closest = r
                .closest
                .filter(|w| max_distance.is_none_or(|m| w.distance < m));
            let answer = closest.map(|w| Answer::Distance {
                distance: w.distance,
                tri_a: w.tri_a,
                tri_b: w.tri_b,
            });
            let beyond = !naive && r.closest.is_none();
            outcome(answer, r.warm_start, r.work, beyond)
        }
        (Effect::Span, _) => {
            let r = pair.span(pa, pb, &SpanOptions::default())?;
            outcome(Some(Answer::Span(r.span())), None, r.work, false)
        }
    })
}
