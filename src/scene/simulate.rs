//! The scene: objects posed over frames, and the scheduler that gives each pair exactly
//! the answer its effect asks for, with the least work that answer needs.

use super::broad::SweepAndPrune;
use super::error::SceneError;
use super::frame::Frame;
use super::narrow::{run_job, Job, Outcome};
use super::object::{inflated_bounds, SceneObject};
use super::report::{
    Answer, EffectWork, Event, EventKind, FrameReport, ObjectId, PairReport, Summary,
};
use super::rules::{Effect, Reach, Rule, RuleTable};
use crate::query::{QueryContext, QueryError, Witness};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::collections::BTreeSet;
use std::time::Instant;

/// What the scheduler keeps of a pair between frames.
#[derive(Clone, Debug)]
struct PairState {
    effect: Effect,
    /// The current answer; `None` is the empty one (not listed).
    answer: Option<Answer>,
    /// The stamp (frame + 1) of the last narrow answer, `None` once culled.
    answered: Option<u64>,
    /// The last distance answer's triangle pair, to warm-start the next.
    witness: Option<Witness>,
}

/// Many objects moving over frames, each pair of objects with the effect its rules give
/// it; [`Scene::step`] answers a frame.
///
/// Per frame the scheduler: moves the world boxes of the objects that moved (from their
/// root volumes, no traversal); runs a sweep-and-prune broad phase whose boxes are inflated
/// by the clearance or `max_distance` the object's rules need, so a culled pair's answer is
/// known empty (no contact, not closer, far); reuses the answer of a pair neither of whose
/// objects moved; and runs, in parallel, the cheapest query that answers each remaining
/// pair: first contact for `contact`, all pairs for `contacts`, the tolerance query for
/// `clearance`, a distance bounded by `max_distance` (within `rel_err`) and warm-started
/// from the previous frame's pair for `distance`, and the span for `span`. With
/// [`Scene::set_naive`] it instead runs every pair's full exact query every frame: the
/// reference the fast path must agree with.
#[derive(Debug)]
pub struct Scene {
    objects: Vec<SceneObject>,
    names: Vec<String>,
    /// Stamp (frame + 1) of each object's last move; 0 for the start pose.
    moved: Vec<u64>,
    rules: RuleTable,
    /// Half of each object's reach: its broad-phase box is inflated by this on every side.
    margins: Vec<f64>,
    broad: SweepAndPrune,
    /// Pairs answered every frame whatever the distance (distances without a limit, spans).
    always: Vec<(u32, u32)>,
    /// Pairs whose effect the broad phase decides (reach `Within`).
    broad_pairs: u64,
    states: FxHashMap<(u32, u32), PairState>,
    /// Pairs with a non-empty answer, in report order.
    listed: BTreeSet<(u32, u32)>,
    naive: bool,
    stamp: u64,
    report: FrameReport,
    summary: Summary,
}

impl Scene {
    /// The scene of checked `objects` and `rules`, at the objects' poses.
    pub(super) fn new(objects: Vec<SceneObject>, rules: Vec<Rule>) -> Scene {
        let matches = |rule: usize, side_b: bool, object: usize| {
            let (Some(r), Some(o)) = (rules.get(rule), objects.get(object)) else {
                return false;
            };
            let selector = if side_b { &r.b } else { &r.a };
            selector == "*" || *selector == o.name || o.groups.iter().any(|g| g == selector)
        };
        let effects = rules.iter().map(|r| r.effect).collect();
        let table = RuleTable::new(effects, objects.len(), matches);
        let margins: Vec<f64> = (0..objects.len())
            .map(|i| 0.5 * table.reach_of(i))
            .collect();
        let (mut always, mut limited, mut broad_pairs, mut with_effect) =
            (Vec::new(), Vec::new(), 0u64, 0u64);
        let n = objects.len();
        for i in 0..n {
            for j in i + 1..n {
                let effect = table.effect(i, j);
                let pair = (i as u32, j as u32);
                match effect.reach() {
                    Reach::Never => continue,
                    Reach::Always => always.push(pair),
                    Reach::Within(_) => {
                        broad_pairs += 1;
                        if let Effect::Distance { .. } = effect {
                            limited.push(pair);
                        }
                    }
                }
                with_effect += 1;
            }
        }
        let boxes = (0..n)
            .map(|i| inflated_bounds(objects.get(i), margins.get(i).copied()))
            .collect();
        let broad = SweepAndPrune::new(boxes, |i, j| {
            matches!(
                table.effect(i as usize, j as usize).reach(),
                Reach::Within(_)
            )
        });
        let mut states = FxHashMap::default();
        for &pair in always.iter().chain(&limited) {
            let effect = table.effect(pair.0 as usize, pair.1 as usize);
            let answer = matches!(
                effect,
                Effect::Distance {
                    max_distance: Some(_),
                    ..
                }
            )
            .then_some(Answer::Far);
            states.insert(
                pair,
                PairState {
                    effect,
                    answer,
                    answered: None,
                    witness: None,
                },
            );
        }
        let names = objects.iter().map(|o| o.name.clone()).collect();
        let summary = Summary {
            objects: n as u64,
            pairs_with_effect: with_effect,
            ..Summary::default()
        };
        Scene {
            moved: vec![0; n],
            objects,
            names,
            rules: table,
            margins,
            broad,
            listed: limited.iter().copied().collect(),
            always,
            broad_pairs,
            states,
            naive: false,
            stamp: 0,
            report: FrameReport::default(),
            summary,
        }
    }

    /// The objects, in scene order (an object's id is its index).
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// The objects' names, in scene order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The id of the object named `name`.
    pub fn object_id(&self, name: &str) -> Option<ObjectId> {
        self.names.iter().position(|n| n == name)
    }

    /// The effect of the pair `(a, b)` (in either order).
    pub fn effect(&self, a: ObjectId, b: ObjectId) -> Effect {
        self.rules.effect(a, b)
    }

    /// Switches between the fast scheduler (the default) and the naive reference: every
    /// pair with an effect, its full exact query, every frame, no broad phase, no reuse,
    /// no warm start.
    pub fn set_naive(&mut self, naive: bool) {
        self.naive = naive;
    }

    /// Whether the naive reference runs.
    pub fn is_naive(&self) -> bool {
        self.naive
    }

    /// The totals of the frames stepped so far.
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    /// The last frame's report.
    pub fn report(&self) -> &FrameReport {
        &self.report
    }

    /// Moves the objects of `frame` (others keep their poses) and answers every pair.
    pub fn step(&mut self, frame: &Frame) -> Result<&FrameReport, SceneError> {
        let started = Instant::now();
        self.stamp += 1;
        let stamp = self.stamp;
        let mut events = Vec::new();
        for &(id, pose) in &frame.poses {
            let Some(object) = self.objects.get_mut(id) else {
                return Err(SceneError::new("frame", format!("no object with id {id}")));
            };
            if object.pose == pose {
                continue;
            }
            object.pose = pose;
            if let Some(m) = self.moved.get_mut(id) {
                *m = stamp;
            }
            let bounds = inflated_bounds(Some(object), self.margins.get(id).copied());
            self.broad.set_box(id as u32, bounds);
        }
        let jobs = if self.naive {
            self.naive_jobs()
        } else {
            self.fast_jobs(&mut events)
        };
        let objects = &self.objects;
        let naive = self.naive;
        let outcomes: Vec<Result<Outcome, QueryError>> = jobs
            .par_iter()
            .with_min_len(4)
            .map_init(QueryContext::new, |context, job| {
                let started = Instant::now();
                let mut outcome = run_job(job, objects, naive, context);
                if let Ok(o) = &mut outcome {
                    o.seconds = started.elapsed().as_secs_f64();
                }
                outcome
            })
            .collect();
        for (job, outcome) in jobs.iter().zip(outcomes) {
            let outcome = outcome.map_err(|e| {
                let (a, b) = (job.pair.0 as usize, job.pair.1 as usize);
                let name = |i: usize| self.names.get(i).cloned().unwrap_or_default();
                SceneError::new("scene", format!("{} and {}: {e}", name(a), name(b)))
            })?;
            self.count(job, &outcome);
            let state = self.states.entry(job.pair).or_insert(PairState {
                effect: job.effect,
                answer: None,
                answered: None,
                witness: None,
            });
            state.answered = Some(stamp);
            state.witness = outcome.witness.or(state.witness);
            let before = state.answer.take();
            set_answer(
                &mut self.listed,
                job.pair,
                state,
                outcome.answer,
                before,
                &mut events,
            );
        }
        events.sort_by_key(|e: &Event| (e.a, e.b));
        let pairs = self
            .listed
            .iter()
            .filter_map(|pair| {
                let answer = self.states.get(pair)?.answer.clone()?;
                Some(PairReport {
                    a: pair.0 as usize,
                    b: pair.1 as usize,
                    answer,
                })
            })
            .collect();
        self.report = FrameReport {
            frame: stamp - 1,
            pairs,
            events,
        };
        self.summary.frames += 1;
        self.summary.seconds += started.elapsed().as_secs_f64();
        Ok(&self.report)
    }

    /// The fast path's jobs: culls and reuses first.
    fn fast_jobs(&mut self, events: &mut Vec<Event>) -> Vec<Job> {
        let table = &self.rules;
        self.broad.update(|i, j| {
            matches!(
                table.effect(i as usize, j as usize).reach(),
                Reach::Within(_)
            )
        });
        // Pairs the broad phase dropped: their answer is now known empty.
        for &pair in self.broad.removed() {
            if let Some(state) = self.states.get_mut(&pair) {
                state.answered = None;
                let before = state.answer.take();
                let empty = matches!(state.effect, Effect::Distance { .. }).then_some(Answer::Far);
                set_answer(&mut self.listed, pair, state, empty, before, events);
            }
        }
        let overlapping = self.broad.overlap_count() as u64;
        self.summary.culled += self.broad_pairs.saturating_sub(overlapping);
        let mut jobs = Vec::new();
        let candidates: Vec<(u32, u32)> = self
            .broad
            .overlaps()
            .chain(self.always.iter().copied())
            .collect();
        for pair in candidates {
            let last_move = |i: u32| self.moved.get(i as usize).copied().unwrap_or(u64::MAX);
            let since = last_move(pair.0).max(last_move(pair.1));
            let effect = self.rules.effect(pair.0 as usize, pair.1 as usize);
            let state = self.states.get(&pair);
            if state.is_some_and(|s| s.answered.is_some_and(|t| t >= since)) {
                self.summary.reused += 1;
                continue;
            }
            jobs.push(Job {
                pair,
                effect,
                warm: state.and_then(|s| s.witness),
            });
        }
        // Deterministic order (the overlap set is a hash set).
        jobs.sort_by_key(|j| j.pair);
        jobs
    }

    /// Every pair with an effect, full exact query.
    fn naive_jobs(&self) -> Vec<Job> {
        let n = self.objects.len();
        let mut jobs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let effect = self.rules.effect(i, j);
                if effect != Effect::None {
                    jobs.push(Job {
                        pair: (i as u32, j as u32),
                        effect,
                        warm: None,
                    });
                }
            }
        }
        jobs
    }

    fn count(&mut self, job: &Job, outcome: &Outcome) {
        let s = &mut self.summary;
        if let Some(work) = s.narrow.of(&job.effect) {
            work.add(&EffectWork {
                queries: 1,
                box_tests: outcome.stats.bv_tests(),
                triangle_tests: outcome.stats.tri_separated + outcome.stats.tri_contact,
                seconds: outcome.seconds,
            });
        }
        s.early_exits += u64::from(outcome.early_exit);
        s.warm_starts += u64::from(job.warm.is_some() && !self.naive);
    }
}

/// Records a pair's new answer: the listing, and an event if its alarm state changed.
fn set_answer(
    listed: &mut BTreeSet<(u32, u32)>,
    pair: (u32, u32),
    state: &mut PairState,
    answer: Option<Answer>,
    before: Option<Answer>,
    events: &mut Vec<Event>,
) {
    let (was, now) = (
        Answer::alarm(before.as_ref()),
        Answer::alarm(answer.as_ref()),
    );
    if was != now {
        let clearance = matches!(state.effect, Effect::Clearance { .. });
        events.push(Event {
            a: pair.0 as usize,
            b: pair.1 as usize,
            kind: EventKind::of(clearance, now),
        });
    }
    if answer.is_some() {
        listed.insert(pair);
    } else {
        listed.remove(&pair);
    }
    state.answer = answer;
}
