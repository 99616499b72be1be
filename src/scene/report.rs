//! What a frame answers, what changed, and what the whole run cost; with their JSON.

use serde_json::{json, Value};

/// An object's index in scene-file order.
pub type ObjectId = usize;

/// The non-empty answer of one pair (an empty one, such as "not in contact", is not
/// listed).
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// `contact`: the two touch.
    Contact,
    /// `contacts`: every contacting triangle pair (input-mesh ids of A's and B's
    /// triangles), sorted.
    Contacts(Vec<(u32, u32)>),
    /// `clearance`: the two come closer than the clearance; a triangle pair that does
    /// (not necessarily the closest).
    Closer {
        /// Triangle of the pair's first object.
        tri_a: u32,
        /// Triangle of the pair's second object.
        tri_b: u32,
        /// Their distance, below the clearance.
        distance: f64,
    },
    /// `distance`: the distance (within the rule's `rel_err`) and a closest pair.
    Distance {
        /// The distance, world units.
        distance: f64,
        /// Triangle of the first object.
        tri_a: u32,
        /// Triangle of the second object.
        tri_b: u32,
    },
    /// `span`: the largest distance between the two.
    Span(f64),
}

impl Answer {
    /// The effect this answers, by its scene-file name.
    pub fn effect_name(&self) -> &'static str {
        match self {
            Answer::Contact => "contact",
            Answer::Contacts(_) => "contacts",
            Answer::Closer { .. } => "clearance",
            Answer::Distance { .. } => "distance",
            Answer::Span(_) => "span",
        }
    }

    /// Whether this answer means "touching" (contact, contacts) or "too close"
    /// (clearance): the states whose changes are events.
    pub(crate) fn alarm(answer: Option<&Answer>) -> bool {
        matches!(
            answer,
            Some(Answer::Contact | Answer::Contacts(_) | Answer::Closer { .. })
        )
    }

    /// The answer's own JSON fields.
    fn fields(&self, out: &mut serde_json::Map<String, Value>) {
        let mut put = |k: &str, v: Value| {
            out.insert(k.to_owned(), v);
        };
        match self {
            Answer::Contact => put("contact", json!(true)),
            Answer::Contacts(pairs) => {
                put("contacts", json!(pairs.len()));
                put(
                    "pairs",
                    json!(pairs.iter().map(|&(a, b)| [a, b]).collect::<Vec<_>>()),
                );
            }
            Answer::Closer {
                tri_a,
                tri_b,
                distance,
            } => {
                put("closer", json!(true));
                put(
                    "witness",
                    json!({"tri_a": tri_a, "tri_b": tri_b, "distance": distance}),
                );
            }
            Answer::Distance {
                distance,
                tri_a,
                tri_b,
            } => {
                put("distance", json!(distance));
                put("tri_a", json!(tri_a));
                put("tri_b", json!(tri_b));
            }
            Answer::Span(span) => put("span", json!(span)),
        }
    }
}

/// One listed pair of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PairReport {
    /// The first object (earlier in the scene file).
    pub a: ObjectId,
    /// The second object.
    pub b: ObjectId,
    /// Its answer.
    pub answer: Answer,
}

/// A change of a pair's state since the previous frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EventKind {
    /// A `contact` or `contacts` pair began to touch.
    ContactStarted,
    /// It stopped touching.
    ContactEnded,
    /// A `clearance` pair came closer than its clearance.
    ClearanceViolated,
    /// It is no longer closer than its clearance.
    ClearanceRestored,
}

impl EventKind {
    /// The JSON name: `contact_started`, `contact_ended`, `clearance_violated`,
    /// `clearance_restored`.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::ContactStarted => "contact_started",
            EventKind::ContactEnded => "contact_ended",
            EventKind::ClearanceViolated => "clearance_violated",
            EventKind::ClearanceRestored => "clearance_restored",
        }
    }

    /// The event of a pair whose alarm state (see [`Answer`]) went to `now`.
    pub(crate) fn of(clearance: bool, now: bool) -> EventKind {
        match (clearance, now) {
            (false, true) => EventKind::ContactStarted,
            (false, false) => EventKind::ContactEnded,
            (true, true) => EventKind::ClearanceViolated,
            (true, false) => EventKind::ClearanceRestored,
        }
    }
}

/// An event of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Event {
    /// The first object.
    pub a: ObjectId,
    /// The second object.
    pub b: ObjectId,
    /// What happened.
    pub kind: EventKind,
}

/// Everything a frame answers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// The frame number (the frames' line index, from 0).
    pub frame: u64,
    /// Every pair with an effect whose answer is not empty, sorted by `(a, b)`.
    pub pairs: Vec<PairReport>,
    /// The changes since the previous frame, sorted by `(a, b)`.
    pub events: Vec<Event>,
}

impl FrameReport {
    /// `{"frame": k, "pairs": [...], "events": [...]}`, objects by `names`.
    pub fn to_json(&self, names: &[String]) -> Value {
        let name = |i: ObjectId| names.get(i).map(String::as_str).unwrap_or("?");
        let pairs: Vec<Value> = self
            .pairs
            .iter()
            .map(|p| {
                let mut object = serde_json::Map::new();
                object.insert("a".into(), json!(name(p.a)));
                object.insert("b".into(), json!(name(p.b)));
                object.insert("effect".into(), json!(p.answer.effect_name()));
                p.answer.fields(&mut object);
                Value::Object(object)
            })
            .collect();
        let events: Vec<Value> = self
            .events
            .iter()
            .map(|e| json!({"a": name(e.a), "b": name(e.b), "event": e.kind.name()}))
            .collect();
        json!({"frame": self.frame, "pairs": pairs, "events": events})
    }
}

impl FrameReport {
    /// How this report (from the fast path) departs from `reference` (the naive path's
    /// report of the same frame), or `None` when it agrees: the same events and the same
    /// pairs with the same answers, except that witnesses may differ where several are
    /// equally right and distances may differ by rounding (1e-9 relative) or, for a rule
    /// with `rel_err`, within it. `effect` gives each pair's effect.
    pub fn disagreement(
        &self,
        reference: &FrameReport,
        effect: impl Fn(ObjectId, ObjectId) -> super::Effect,
    ) -> Option<String> {
        let frame = self.frame;
        if self.events != reference.events {
            return Some(format!(
                "frame {frame}: events {:?}, reference {:?}",
                self.events, reference.events
            ));
        }
        if self.pairs.len() != reference.pairs.len() {
            let ids = |r: &FrameReport| r.pairs.iter().map(|p| (p.a, p.b)).collect::<Vec<_>>();
            return Some(format!(
                "frame {frame}: pairs {:?}, reference {:?}",
                ids(self),
                ids(reference)
            ));
        }
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + y.abs());
        for (p, q) in self.pairs.iter().zip(&reference.pairs) {
            let (rel_err, clearance) = match effect(p.a, p.b) {
                super::Effect::Distance { rel_err, .. } => (rel_err, f64::INFINITY),
                super::Effect::Clearance { clearance } => (0.0, clearance),
                _ => (0.0, f64::INFINITY),
            };
            let agree = (p.a, p.b) == (q.a, q.b)
                && match (&p.answer, &q.answer) {
                    (Answer::Closer { distance: x, .. }, Answer::Closer { distance: y, .. }) => {
                        // Any pair closer than the clearance is a right witness.
                        *x < clearance && *y < clearance
                    }
                    (
                        Answer::Distance { distance: x, .. },
                        Answer::Distance { distance: y, .. },
                    ) => {
                        // Within rounding either way, or above by at most `rel_err`: `close`
                        // already takes the rounding below `y`.
                        close(*x, *y) || (*x >= *y && *x <= y * (1.0 + rel_err) + 1e-9 * (1.0 + y))
                    }
                    (Answer::Span(x), Answer::Span(y)) => close(*x, *y),
                    (x, y) => x == y,
                };
            if !agree {
                return Some(format!(
                    "frame {frame}: pair ({}, {}) answers {:?}, reference ({}, {}) {:?}",
                    p.a, p.b, p.answer, q.a, q.b, q.answer
                ));
            }
        }
        None
    }
}

/// The narrow-phase work spent on one effect.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EffectWork {
    /// Queries run.
    pub queries: u64,
    /// Bounding-volume pair tests.
    pub box_tests: u64,
    /// Triangle pair tests.
    pub triangle_tests: u64,
    /// Time in those queries (seconds, summed over threads).
    pub seconds: f64,
}

impl EffectWork {
    pub(crate) fn add(&mut self, other: &EffectWork) {
        self.queries += other.queries;
        self.box_tests += other.box_tests;
        self.triangle_tests += other.triangle_tests;
        self.seconds += other.seconds;
    }

    fn to_json(self) -> Value {
        json!({
            "queries": self.queries,
            "box_tests": self.box_tests,
            "triangle_tests": self.triangle_tests,
            "seconds": self.seconds,
        })
    }
}

/// Narrow-phase work by the effect it answered.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NarrowWork {
    /// First-contact queries (`contact`).
    pub contact: EffectWork,
    /// All-pairs collision queries (`contacts`).
    pub contacts: EffectWork,
    /// Tolerance queries (`clearance`).
    pub clearance: EffectWork,
    /// Distance queries (`distance`).
    pub distance: EffectWork,
    /// Span queries (`span`).
    pub span: EffectWork,
}

impl NarrowWork {
    /// Each effect's work with the effect's name, in the order of the scene file's list.
    pub fn by_effect(&self) -> [(&'static str, &EffectWork); 5] {
        [
            ("contact", &self.contact),
            ("contacts", &self.contacts),
            ("clearance", &self.clearance),
            ("distance", &self.distance),
            ("span", &self.span),
        ]
    }

    /// The work of `effect` (`None` for `none`, which never runs a query).
    pub(crate) fn of(&mut self, effect: &super::Effect) -> Option<&mut EffectWork> {
        use super::Effect;
        match effect {
            Effect::None => None,
            Effect::Contact => Some(&mut self.contact),
            Effect::Contacts => Some(&mut self.contacts),
            Effect::Clearance { .. } => Some(&mut self.clearance),
            Effect::Distance { .. } => Some(&mut self.distance),
            Effect::Span => Some(&mut self.span),
        }
    }

    /// All effects together.
    pub fn total(&self) -> EffectWork {
        let mut total = EffectWork::default();
        for (_, work) in self.by_effect() {
            total.add(work);
        }
        total
    }
}

/// What a run of frames cost, and what the scheduler skipped.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Frames stepped.
    pub frames: u64,
    /// Objects in the scene.
    pub objects: u64,
    /// Pairs of distinct objects whose effect is not `none`.
    pub pairs_with_effect: u64,
    /// Pair-frames the broad phase proved empty (no contact, not closer, beyond
    /// `max_distance`) without a narrow query, summed over frames.
    pub culled: u64,
    /// Pair-frames answered by reusing the previous answer (neither object moved).
    pub reused: u64,
    /// Narrow-phase queries and their work, by effect.
    pub narrow: NarrowWork,
    /// Narrow queries that stopped early: a first contact found, a clearance violated,
    /// or a limited distance found beyond its `max_distance`.
    pub early_exits: u64,
    /// Distance queries started from the previous frame's witness pair.
    pub warm_starts: u64,
    /// Wall time spent in frames (seconds).
    pub seconds: f64,
}

impl Summary {
    /// Frames per second of wall time.
    pub fn frames_per_second(&self) -> f64 {
        if self.seconds > 0.0 {
            self.frames as f64 / self.seconds
        } else {
            0.0
        }
    }

    /// `{"summary": {...}}`; `mode` is `fast` or `naive`.
    pub fn to_json(&self, mode: &str) -> Value {
        let mut narrow = serde_json::Map::new();
        for (name, work) in self.narrow.by_effect() {
            narrow.insert(name.to_owned(), work.to_json());
        }
        let total = self.narrow.total();
        narrow.insert("total".to_owned(), total.to_json());
        json!({"summary": {
            "mode": mode,
            "frames": self.frames,
            "objects": self.objects,
            "pairs_with_effect": self.pairs_with_effect,
            "culled": self.culled,
            "reused": self.reused,
            "narrow": narrow,
            "early_exits": self.early_exits,
            "warm_starts": self.warm_starts,
            "triangle_tests": total.triangle_tests,
            "box_tests": total.box_tests,
            "seconds": self.seconds,
            "frames_per_second": self.frames_per_second(),
        }})
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Effect;

    /// A frame whose one listed pair is objects 0 and `b`.
    fn one_pair(b: ObjectId, answer: Answer) -> FrameReport {
        FrameReport {
            frame: 7,
            pairs: vec![PairReport { a: 0, b, answer }],
            events: Vec::new(),
        }
    }

    fn distance(distance: f64) -> Answer {
        Answer::Distance {
            distance,
            tri_a: 3,
            tri_b: 4,
        }
    }

    /// The fast path's distance may exceed the reference's by the rule's `rel_err` and
    /// rounding (1e-9 of the distance plus 1e-9), and fall below it by rounding only; a
    /// span may differ by rounding either way, a clearance's witness by anything below it.
    #[test]
    fn distances_agree_within_the_rules_error_and_rounding() {
        // Large and small values: the rounding's absolute term matters for the small.
        for y in [10.0, 0.1] {
            let rounding = 1e-9 * (1.0 + y);
            let reference = one_pair(1, distance(y));
            let agrees = |x: f64, rel_err: f64| {
                let effect = |_: ObjectId, _: ObjectId| Effect::Distance {
                    rel_err,
                    max_distance: None,
                };
                one_pair(1, distance(x))
                    .disagreement(&reference, effect)
                    .is_none()
            };
            for rel_err in [0.0, 0.01] {
                let top = y * (1.0 + rel_err);
                assert!(agrees(top + 0.9 * rounding, rel_err));
                assert!(!agrees(top + 1.1 * rounding, rel_err));
                assert!(agrees(y - 0.9 * rounding, rel_err));
                assert!(!agrees(y - 1.1 * rounding, rel_err));
            }
            // Spans agree to rounding only.
            let span = one_pair(1, Answer::Span(y));
            let spans_agree = |x: f64| {
                one_pair(1, Answer::Span(x))
                    .disagreement(&span, |_, _| Effect::Span)
                    .is_none()
            };
            assert!(spans_agree(y + 0.9 * rounding) && spans_agree(y - 0.9 * rounding));
            assert!(!spans_agree(y + 1.1 * rounding) && !spans_agree(y - 1.1 * rounding));
        }
        // Any witness closer than the clearance is right, and one that is not is wrong.
        let closer = |distance: f64| Answer::Closer {
            tri_a: 1,
            tri_b: 2,
            distance,
        };
        let clearance = |_: ObjectId, _: ObjectId| Effect::Clearance { clearance: 0.5 };
        let violated = one_pair(1, closer(0.1));
        assert!(one_pair(1, closer(0.45))
            .disagreement(&violated, clearance)
            .is_none());
        assert!(one_pair(1, closer(0.5))
            .disagreement(&violated, clearance)
            .is_some());
        // Either side's witness: a reference at the clearance is wrong too.
        assert!(violated
            .disagreement(&one_pair(1, closer(0.5)), clearance)
            .is_some());
        // Another pair, or another kind of answer, disagrees whatever the distances.
        let effect = |_: ObjectId, _: ObjectId| Effect::Span;
        let reference = one_pair(1, distance(10.0));
        assert!(one_pair(2, distance(10.0))
            .disagreement(&reference, effect)
            .is_some());
        assert!(one_pair(1, Answer::Span(10.0))
            .disagreement(&reference, effect)
            .is_some());
    }

    /// The effects in the scene file's order, one of each kind.
    fn effects() -> [Effect; 5] {
        [
            Effect::Contact,
            Effect::Contacts,
            Effect::Clearance { clearance: 0.5 },
            Effect::Distance {
                rel_err: 0.0,
                max_distance: None,
            },
            Effect::Span,
        ]
    }

    /// A frame's JSON: each pair's objects by name (`?` for an id without one), its effect
    /// by the scene-file name, and the answer's own fields; each event by its name.
    #[test]
    fn each_answer_is_written_with_its_effects_name_and_fields() {
        let names = ["base".to_owned(), "arm".to_owned()];
        let answers = [
            (Answer::Contact, json!({"contact": true})),
            (
                Answer::Contacts(vec![(1, 2), (3, 4)]),
                json!({"contacts": 2, "pairs": [[1, 2], [3, 4]]}),
            ),
            (
                Answer::Closer {
                    tri_a: 5,
                    tri_b: 6,
                    distance: 0.25,
                },
                json!({"closer": true, "witness": {"tri_a": 5, "tri_b": 6, "distance": 0.25}}),
            ),
            (
                distance(1.5),
                json!({"distance": 1.5, "tri_a": 3, "tri_b": 4}),
            ),
            (Answer::Span(2.5), json!({"span": 2.5})),
        ];
        let kinds = [
            (EventKind::ContactStarted, "contact_started"),
            (EventKind::ContactEnded, "contact_ended"),
            (EventKind::ClearanceViolated, "clearance_violated"),
            (EventKind::ClearanceRestored, "clearance_restored"),
            (EventKind::ContactStarted, "contact_started"),
        ];
        for (((answer, fields), effect), (kind, event)) in
            answers.into_iter().zip(effects()).zip(kinds)
        {
            let mut pair = json!({"a": "base", "b": "?", "effect": effect.name()});
            pair.as_object_mut()
                .unwrap()
                .extend(fields.as_object().unwrap().clone());
            let report = FrameReport {
                frame: 7,
                pairs: vec![PairReport { a: 0, b: 2, answer }],
                events: vec![Event { a: 1, b: 0, kind }],
            };
            let expected = json!({
                "frame": 7,
                "pairs": [pair],
                "events": [{"a": "arm", "b": "base", "event": event}],
            });
            assert_eq!(report.to_json(&names), expected);
        }
    }

    /// Each effect's work is kept under its own name, and the summary's totals add them all.
    #[test]
    fn the_summary_keeps_each_effects_work_and_totals_them() {
        for effect in effects() {
            let mut narrow = NarrowWork::default();
            narrow.of(&effect).unwrap().queries = 1;
            let named: Vec<&str> = (narrow.by_effect().into_iter())
                .filter(|(_, w)| w.queries == 1)
                .map(|(name, _)| name)
                .collect();
            assert_eq!(named, [effect.name()]);
        }
        assert!(NarrowWork::default().of(&Effect::None).is_none());

        let work = |k: u64| EffectWork {
            queries: k,
            box_tests: 10 * k,
            triangle_tests: 100 * k,
            seconds: 0.5 * k as f64,
        };
        let summary = Summary {
            frames: 4,
            objects: 3,
            pairs_with_effect: 2,
            culled: 5,
            reused: 6,
            narrow: NarrowWork {
                contact: work(1),
                contacts: work(2),
                clearance: work(3),
                distance: work(4),
                span: work(5),
            },
            early_exits: 7,
            warm_starts: 8,
            seconds: 2.0,
        };
        let total =
            json!({"queries": 15, "box_tests": 150, "triangle_tests": 1500, "seconds": 7.5});
        assert_eq!(
            summary.to_json("naive"),
            json!({"summary": {
                "mode": "naive",
                "frames": 4,
                "objects": 3,
                "pairs_with_effect": 2,
                "culled": 5,
                "reused": 6,
                "narrow": {
                    "contact": work(1).to_json(),
                    "contacts": work(2).to_json(),
                    "clearance": work(3).to_json(),
                    "distance": work(4).to_json(),
                    "span": work(5).to_json(),
                    "total": total,
                },
                "early_exits": 7,
                "warm_starts": 8,
                "triangle_tests": 1500,
                "box_tests": 150,
                "seconds": 2.0,
                "frames_per_second": 2.0,
            }})
        );
        assert_eq!(work(3).to_json()["seconds"], 1.5);
        assert_eq!(Summary::default().frames_per_second(), 0.0);
    }
}
