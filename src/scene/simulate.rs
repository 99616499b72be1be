//! The scene: objects posed over frames, and the scheduler that gives each pair exactly
//! the answer its effect asks for, with the least work that answer needs.

use super::broad::{Bounds, SweepAndPrune};
use super::error::SceneError;
use super::report::{
    Answer, EffectWork, Event, EventKind, FrameReport, ObjectId, PairReport, Summary,
};
use super::rules::{Effect, Reach, RuleTable};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::query::{
    CollideOptions, DistanceOptions, PairQuery, Pose, QueryContext, QueryError, Side, SpanOptions,
    ToleranceOptions, WarmStart, Work,
};
use crate::tree::TreeView;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::collections::BTreeSet;
use std::sync::Arc;
use std::time::Instant;

/// One object of a scene: a name, the tree it uses (shared with other objects of the same
/// asset), its groups and its current pose.
#[derive(Clone, Debug)]
pub struct SceneObject {
    /// Unique name, `[A-Za-z0-9_.-]+`.
    pub name: String,
    /// Groups it belongs to (same characters).
    pub groups: Vec<String>,
    /// Its tree.
    pub asset: Arc<ObbtFile>,
    /// Where it is now.
    pub pose: Pose,
}

/// A rule: pairs of an object matched by `a` and one matched by `b` (in either order) get
/// `effect`. A side is an object name, a group name, or `*` (every object).
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    /// First side.
    pub a: String,
    /// Second side.
    pub b: String,
    /// What the pairs ask for.
    pub effect: Effect,
}

/// Which item of a scene description a problem is about, for locating it in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Item {
    Object(usize),
    Rule(usize),
}

/// A problem found while building a scene, before it is placed in a file.
#[derive(Clone, Debug)]
pub(crate) struct Problem {
    pub(crate) item: Item,
    pub(crate) field: &'static str,
    pub(crate) message: String,
}

impl Problem {
    /// As a located error: `rule 3, field a: ...` in `source`, at `line` when known.
    pub(crate) fn located(self, source: &str, line: Option<usize>) -> SceneError {
        let item = match self.item {
            Item::Object(k) => format!("object {}, field {}", k + 1, self.field),
            Item::Rule(k) => format!("rule {}, field {}", k + 1, self.field),
        };
        let e = SceneError::new(source, self.message).in_field(item);
        match line {
            Some(line) => e.at_line(line),
            None => e,
        }
    }
}

/// Collects objects and rules, then checks them into a [`Scene`].
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    objects: Vec<SceneObject>,
    rules: Vec<Rule>,
}

/// Whether `name` is a valid object or group name.
fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-'))
}

impl SceneBuilder {
    /// An empty scene description.
    pub fn new() -> SceneBuilder {
        SceneBuilder::default()
    }

    /// Adds an object; its id is its position in the order of addition.
    pub fn object(
        &mut self,
        name: &str,
        asset: Arc<ObbtFile>,
        groups: &[&str],
        pose: Pose,
    ) -> ObjectId {
        self.objects.push(SceneObject {
            name: name.to_owned(),
            groups: groups.iter().map(|g| (*g).to_owned()).collect(),
            asset,
            pose,
        });
        self.objects.len() - 1
    }

    /// Adds a rule; later rules override earlier ones for the pairs both match.
    pub fn rule(&mut self, a: &str, b: &str, effect: Effect) {
        self.rules.push(Rule {
            a: a.to_owned(),
            b: b.to_owned(),
            effect,
        });
    }

    /// Checks the description and builds the scene at its start poses.
    pub fn build(self) -> Result<Scene, SceneError> {
        self.checked().map_err(|p| p.located("scene", None))
    }

    pub(crate) fn checked(self) -> Result<Scene, Problem> {
        let problem = |item, field, message: String| Problem {
            item,
            field,
            message,
        };
        let mut names: FxHashMap<&str, usize> = FxHashMap::default();
        for (k, o) in self.objects.iter().enumerate() {
            if !valid_name(&o.name) {
                let m = format!("{:?} is not a name of letters, digits, _ . -", o.name);
                return Err(problem(Item::Object(k), "name", m));
            }
            if let Some(first) = names.insert(&o.name, k) {
                let m = format!("{:?} is also object {}", o.name, first + 1);
                return Err(problem(Item::Object(k), "name", m));
            }
            if let Some(g) = o.groups.iter().find(|g| !valid_name(g)) {
                let m = format!("{g:?} is not a name of letters, digits, _ . -");
                return Err(problem(Item::Object(k), "groups", m));
            }
        }
        // One volume type and precision for the whole scene.
        if let Some(first) = self.objects.first() {
            let kind = |o: &SceneObject| (o.asset.bv_kind(), o.asset.precision());
            if let Some((k, other)) = self
                .objects
                .iter()
                .enumerate()
                .find(|(_, o)| kind(o) != kind(first))
            {
                let describe = |o: &SceneObject| {
                    format!(
                        "{} {}",
                        o.asset.bv_kind().name(),
                        o.asset.precision().name()
                    )
                };
                let m = format!(
                    "object {:?} stores {} but {:?} stores {}; a scene's assets share one volume type and precision",
                    other.name,
                    describe(other),
                    first.name,
                    describe(first)
                );
                return Err(problem(Item::Object(k), "asset", m));
            }
        }
        let known = |selector: &str| {
            selector == "*"
                || names.contains_key(selector)
                || self
                    .objects
                    .iter()
                    .any(|o| o.groups.iter().any(|g| g == selector))
        };
        for (k, r) in self.rules.iter().enumerate() {
            for (field, side) in [("a", &r.a), ("b", &r.b)] {
                if !known(side) {
                    let m = format!("no object or group named {side:?}");
                    return Err(problem(Item::Rule(k), field, m));
                }
            }
            let positive = |v: f64| v.is_finite() && v > 0.0;
            match r.effect {
                Effect::Clearance { clearance } if !positive(clearance) => {
                    let m = format!("must be a finite number > 0, got {clearance}");
                    return Err(problem(Item::Rule(k), "clearance", m));
                }
                Effect::Distance { rel_err, .. } if !(rel_err.is_finite() && rel_err >= 0.0) => {
                    let m = format!("must be a finite number >= 0, got {rel_err}");
                    return Err(problem(Item::Rule(k), "rel_err", m));
                }
                Effect::Distance {
                    max_distance: Some(limit),
                    ..
                } if !positive(limit) => {
                    let m = format!("must be a finite number > 0, got {limit}");
                    return Err(problem(Item::Rule(k), "max_distance", m));
                }
                _ => {}
            }
        }
        Ok(Scene::new(self.objects, self.rules))
    }
}

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

/// A narrow query to run.
#[derive(Clone, Copy, Debug)]
struct Job {
    pair: (u32, u32),
    effect: Effect,
    warm_start: Option<WarmStart>,
}

/// A narrow query's result.
#[derive(Clone, Debug)]
struct Outcome {
    answer: Option<Answer>,
    /// The distance answer's triangle pair, to warm-start the next.
    warm_start: Option<WarmStart>,
    work: Work,
    early_exit: bool,
    /// Time the query took.
    seconds: f64,
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

/// The world box of a tree's root volume under a pose.
struct RootBounds<'p>(&'p Pose);

impl TreeVisitor for RootBounds<'_> {
    type Output = Option<Bounds>;
    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Option<Bounds> {
        let root = tree.node(0)?;
        let b = root.bv.world_aabb(self.0);
        Some([b.min, b.max])
    }
}

impl Scene {
    fn new(objects: Vec<SceneObject>, rules: Vec<Rule>) -> Scene {
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
                    warm_start: None,
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
                warm_start: None,
            });
            state.answered = Some(stamp);
            state.warm_start = outcome.warm_start.or(state.warm_start);
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
                warm_start: state.and_then(|s| s.warm_start),
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
                        warm_start: None,
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
                box_tests: outcome.work.bv_tests(),
                triangle_tests: outcome.work.tri_separated + outcome.work.tri_contact,
                seconds: outcome.seconds,
            });
        }
        s.early_exits += u64::from(outcome.early_exit);
        s.warm_starts += u64::from(job.warm_start.is_some() && !self.naive);
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

/// An object's world box, inflated by `margin` on every side; an empty box far away for an
/// object whose tree has no root (a damaged file: it can then meet nothing).
fn inflated_bounds(object: Option<&SceneObject>, margin: Option<f64>) -> Bounds {
    let far = [[f64::INFINITY; 3], [f64::INFINITY; 3]];
    let Some(object) = object else { return far };
    let Ok(Some(b)) = object.asset.visit(RootBounds(&object.pose)) else {
        return far;
    };
    let m = margin.unwrap_or(0.0);
    [b[0].map(|v| v - m), b[1].map(|v| v + m)]
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
            let answer = closest.map_or(Answer::Far, |w| Answer::Distance {
                distance: w.distance,
                tri_a: w.tri_a,
                tri_b: w.tri_b,
            });
            let beyond = !naive && r.closest.is_none();
            outcome(Some(answer), r.warm_start, r.work, beyond)
        }
        (Effect::Span, _) => {
            let r = pair.span(pa, pb, &SpanOptions::default())?;
            outcome(Some(Answer::Span(r.span())), None, r.work, false)
        }
    })
}

/// The poses one frame changes; objects not named keep theirs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// `(object, pose)`, in any order; a later entry for the same object wins.
    pub poses: Vec<(ObjectId, Pose)>,
}

impl Frame {
    /// A frame that moves nothing.
    pub fn new() -> Frame {
        Frame::default()
    }

    /// Moves `object` to `pose` in this frame.
    pub fn set(&mut self, object: ObjectId, pose: Pose) -> &mut Frame {
        self.poses.push((object, pose));
        self
    }
}
