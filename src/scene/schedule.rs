//! The scheduler: which pairs a frame must query, which answers it knows without a query
//! (culled by the broad phase, or reused because neither object moved), and each pair's
//! answer and events from frame to frame.

use super::broad::SweepAndPrune;
use super::narrow::{Job, Outcome};
use super::object::{inflated_bounds, SceneObject};
use super::report::{Answer, EffectWork, Event, EventKind, ObjectId, PairReport, Summary};
use super::rules::{Effect, Reach, RuleTable};
use crate::query::WarmStart;
use rustc_hash::FxHashMap;
use std::collections::BTreeSet;

/// What the scheduler keeps of a pair between frames.
#[derive(Clone, Debug)]
struct PairState {
    effect: Effect,
    /// The current answer; `None` is the empty one (not listed).
    answer: Option<Answer>,
    /// The stamp (frame + 1) of the last narrow answer, `None` once culled.
    answered: Option<u64>,
    /// The last distance answer's triangle pair, to warm-start the next.
    warm_start: Option<WarmStart>,
}

/// The scheduler's state between frames: the rules, when each object last moved, the
/// broad phase over the objects' inflated world boxes, and every pair's current answer.
/// See [`super::Scene`] for what a frame does with it.
#[derive(Debug)]
pub(super) struct Schedule {
    rules: RuleTable,
    /// Stamp (frame + 1) of each object's last move; 0 for the start pose. One per object.
    moved: Vec<u64>,
    /// Half of each object's reach: its broad-phase box is inflated by this on every side.
    margins: Vec<f64>,
    broad: SweepAndPrune,
    /// Pairs answered every frame whatever the distance (distances without a limit, spans).
    always: Vec<(u32, u32)>,
    /// Pairs whose effect the broad phase decides (reach `Within`).
    broad_pairs: u64,
    /// Pairs of distinct objects whose effect is not `none`.
    pairs_with_effect: u64,
    states: FxHashMap<(u32, u32), PairState>,
    /// Pairs with a non-empty answer, in report order.
    listed: BTreeSet<(u32, u32)>,
    naive: bool,
    /// The current frame + 1; 0 before the first.
    stamp: u64,
}

impl Schedule {
    /// The schedule of `objects` at their current poses under the rules of `table`, before
    /// any frame: every pair empty.
    pub(super) fn new(objects: &[SceneObject], table: RuleTable) -> Schedule {
        let margins: Vec<f64> = (0..objects.len())
            .map(|i| 0.5 * table.reach_of(i))
            .collect();
        let (mut always, mut broad_pairs, mut with_effect) = (Vec::new(), 0u64, 0u64);
        let n = objects.len();
        for i in 0..n {
            for j in i + 1..n {
                let effect = table.effect(i, j);
                let pair = (i as u32, j as u32);
                match effect.reach() {
                    Reach::Never => continue,
                    Reach::Always => always.push(pair),
                    Reach::Within(_) => broad_pairs += 1,
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
        for &pair in &always {
            let effect = table.effect(pair.0 as usize, pair.1 as usize);
            states.insert(
                pair,
                PairState {
                    effect,
                    answer: None,
                    answered: None,
                    warm_start: None,
                },
            );
        }
        Schedule {
            rules: table,
            moved: vec![0; n],
            margins,
            broad,
            listed: BTreeSet::new(),
            always,
            broad_pairs,
            pairs_with_effect: with_effect,
            states,
            naive: false,
            stamp: 0,
        }
    }

    /// The effect of the pair `(a, b)` (in either order).
    pub(super) fn effect(&self, a: ObjectId, b: ObjectId) -> Effect {
        self.rules.effect(a, b)
    }

    /// Pairs of distinct objects whose effect is not `none`.
    pub(super) fn pairs_with_effect(&self) -> u64 {
        self.pairs_with_effect
    }

    /// Switches between the fast scheduler and the naive reference (see
    /// [`super::Scene::set_naive`]).
    pub(super) fn set_naive(&mut self, naive: bool) {
        self.naive = naive;
    }

    /// Whether the naive reference runs.
    pub(super) fn is_naive(&self) -> bool {
        self.naive
    }

    /// Starts the next frame and returns its number (from 0).
    pub(super) fn begin_frame(&mut self) -> u64 {
        self.stamp += 1;
        self.stamp - 1
    }

    /// Notes that object `id`, now `object`, moved in this frame: its broad-phase box
    /// follows it and its pairs' answers are no longer current.
    pub(super) fn moved(&mut self, id: ObjectId, object: &SceneObject) {
        if let Some(m) = self.moved.get_mut(id) {
            *m = self.stamp;
        }
        let bounds = inflated_bounds(Some(object), self.margins.get(id).copied());
        self.broad.set_box(id as u32, bounds);
    }

    /// This frame's narrow queries, once every object that moved has been noted; on the
    /// fast path the answers of the pairs the broad phase culls are set (their events
    /// pushed to `events`) and culled and reused pairs are counted in `summary`.
    pub(super) fn jobs(&mut self, summary: &mut Summary, events: &mut Vec<Event>) -> Vec<Job> {
        if self.naive {
            self.naive_jobs()
        } else {
            self.fast_jobs(summary, events)
        }
    }

    /// The fast path's jobs: culls and reuses first.
    fn fast_jobs(&mut self, summary: &mut Summary, events: &mut Vec<Event>) -> Vec<Job> {
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
                set_answer(&mut self.listed, pair, state, None, before, events);
            }
        }
        let overlapping = self.broad.overlap_count() as u64;
        summary.culled += self.broad_pairs.saturating_sub(overlapping);
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
                summary.reused += 1;
                continue;
            }
            jobs.push(Job {
                pair,
                effect,
                warm_start: state.and_then(|s| s.warm_start),
            });
        }
        // Deterministic order (the overlap set is a hash set).
        jobs.sort_by_key(|j| j.pair);
        jobs
    }

    /// Every pair with an effect, full exact query.
    fn naive_jobs(&self) -> Vec<Job> {
        let n = self.moved.len();
        let mut jobs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let effect = self.rules.effect(i, j);
                if effect != Effect::None {
                    jobs.push(Job {
                        pair: (i as u32, j as u32),
                        effect,
                        warm_start: None,
                    });
                }
            }
        }
        jobs
    }

    /// Records a job's outcome: its work in `summary`, the pair's new answer, and an event
    /// in `events` if the pair's alarm state changed.
    pub(super) fn record(
        &mut self,
        job: &Job,
        outcome: Outcome,
        summary: &mut Summary,
        events: &mut Vec<Event>,
    ) {
        self.count(job, &outcome, summary);
        let state = self.states.entry(job.pair).or_insert(PairState {
            effect: job.effect,
            answer: None,
            answered: None,
            warm_start: None,
        });
        state.answered = Some(self.stamp);
        state.warm_start = outcome.warm_start.or(state.warm_start);
        let before = state.answer.take();
        set_answer(
            &mut self.listed,
            job.pair,
            state,
            outcome.answer,
            before,
            events,
        );
    }

    /// Adds a job's work to `summary`.
    fn count(&self, job: &Job, outcome: &Outcome, s: &mut Summary) {
        if let Some(work) = s.narrow.of(&job.effect) {
            work.add(&EffectWork {
                queries: 1,
                box_tests: outcome.work.bv_tests(),
                triangle_tests: outcome.work.tri_tests(),
                seconds: outcome.seconds,
            });
        }
        s.early_exits += u64::from(outcome.early_exit);
        s.warm_starts += u64::from(job.warm_start.is_some() && !self.naive);
    }

    /// The pairs with a non-empty answer, sorted by `(a, b)`.
    pub(super) fn listed(&self) -> Vec<PairReport> {
        self.listed
            .iter()
            .filter_map(|pair| {
                let answer = self.states.get(pair)?.answer.clone()?;
                Some(PairReport {
                    a: pair.0 as usize,
                    b: pair.1 as usize,
                    answer,
                })
            })
            .collect()
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
