//! The scene: objects posed over frames; a step applies a frame's moves, runs the narrow
//! queries the schedule asks for, and reports.

use super::error::SceneError;
use super::frame::Frame;
use super::narrow::run_jobs;
use super::object::SceneObject;
use super::report::{Event, FrameReport, ObjectId, Summary};
use super::rules::{Effect, Rule, RuleTable};
use super::schedule::Schedule;
use std::time::Instant;

/// Many objects moving over frames, each pair of objects with the effect its rules give
/// it; [`Scene::step`] answers a frame.
///
/// Per frame the scheduler: moves the world boxes of the objects that moved (from their
/// root volumes, no traversal); runs a sweep-and-prune broad phase whose boxes are inflated
/// by the clearance or `max_distance` the object's rules need, so a culled pair's answer is
/// known empty (no contact, not closer, beyond `max_distance`); reuses the answer of a pair
/// neither of whose objects moved; and runs, in parallel, the cheapest query that answers
/// each remaining pair: first contact for `contact`, all pairs for `contacts`, the
/// tolerance query for `clearance`, a distance bounded by `max_distance` (within `rel_err`)
/// and warm-started from the previous frame's pair for `distance`, and the span for `span`.
/// With [`Scene::set_naive`] it instead runs every pair's full exact query every frame: the
/// reference the fast path must agree with.
#[derive(Debug)]
pub struct Scene {
    objects: Vec<SceneObject>,
    names: Vec<String>,
    /// Which pairs each frame queries, and every pair's answer.
    schedule: Schedule,
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
        let schedule = Schedule::new(&objects, table);
        let names = objects.iter().map(|o| o.name.clone()).collect();
        let summary = Summary {
            objects: objects.len() as u64,
            pairs_with_effect: schedule.pairs_with_effect(),
            ..Summary::default()
        };
        Scene {
            objects,
            names,
            schedule,
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
        self.schedule.effect(a, b)
    }

    /// Switches between the fast scheduler (the default) and the naive reference: every
    /// pair with an effect, its full exact query, every frame, no broad phase, no reuse,
    /// no warm start.
    pub fn set_naive(&mut self, naive: bool) {
        self.schedule.set_naive(naive);
    }

    /// Whether the naive reference runs.
    pub fn is_naive(&self) -> bool {
        self.schedule.is_naive()
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
    ///
    /// # Errors
    ///
    /// A [`SceneError`] with origin `frame` if the frame names an object id the scene does
    /// not have, or with origin `scene` naming the two objects if a pair's query fails (its
    /// [`QueryError`](crate::query::QueryError) is the `source`).
    ///
    /// # Examples
    ///
    /// See the [module example](super) and [`load`](super::load).
    ///
    /// ```
    /// use obbtree::format::ObbtFile;
    /// use obbtree::query::Pose;
    /// use obbtree::scene::{Effect, Frame, SceneBuilder};
    /// use std::sync::Arc;
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let table = Arc::new(ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?);
    /// let mut scene = SceneBuilder::new();
    /// let a = scene.object("a", table.clone(), &["furniture"], Pose::identity());
    /// let b = scene.object("b", table, &["furniture"], Pose::translation(10.0, 0.0, 0.0));
    /// scene.rule("furniture", "furniture", Effect::Contact);
    /// let mut scene = scene.build()?;
    /// assert!(scene.step(&Frame::new())?.pairs.is_empty());
    /// assert!(!scene.step(Frame::new().set(b, Pose::identity()))?.pairs.is_empty());
    /// assert!(scene.step(Frame::new().set(a + 2, Pose::identity())).is_err()); // no such object
    /// # Ok(())
    /// # }
    /// ```
    pub fn step(&mut self, frame: &Frame) -> Result<&FrameReport, SceneError> {
        let started = Instant::now();
        let number = self.schedule.begin_frame();
        let mut events = Vec::new();
        for &(id, pose) in &frame.poses {
            let Some(object) = self.objects.get_mut(id) else {
                return Err(SceneError::new("frame", format!("no object with id {id}")));
            };
            if object.pose == pose {
                continue;
            }
            object.pose = pose;
            self.schedule.moved(id, object);
        }
        let jobs = self.schedule.jobs(&mut self.summary, &mut events);
        let outcomes = run_jobs(&jobs, &self.objects, self.schedule.is_naive());
        for (job, outcome) in jobs.iter().zip(outcomes) {
            let outcome = outcome.map_err(|e| {
                let (a, b) = (job.pair.0 as usize, job.pair.1 as usize);
                let name = |i: usize| self.names.get(i).cloned().unwrap_or_default();
                SceneError::new("scene", format!("{} and {}: {e}", name(a), name(b))).caused_by(e)
            })?;
            self.schedule
                .record(job, outcome, &mut self.summary, &mut events);
        }
        events.sort_by_key(|e: &Event| (e.a, e.b));
        self.report = FrameReport {
            frame: number,
            pairs: self.schedule.listed(),
            events,
        };
        self.summary.frames += 1;
        self.summary.seconds += started.elapsed().as_secs_f64();
        Ok(&self.report)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Effect, Frame, SceneBuilder};
    use crate::format::ObbtFile;
    use crate::query::Pose;
    use std::sync::Arc;

    /// What the bindings and the CLI read a scene by: its objects and names in scene
    /// order, an id by name, the mode, the last report, and the summary's frames and time
    /// after steps.
    #[test]
    fn a_scene_is_read_back_by_its_accessors() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt");
        let table = Arc::new(ObbtFile::open(path).unwrap());
        let far = Pose::translation(10.0, 0.0, 0.0);
        let mut builder = SceneBuilder::new();
        builder.object("a", table.clone(), &["g"], Pose::identity());
        builder.object("b", table, &["g"], far);
        builder.rule("g", "g", Effect::Contact);
        let mut scene = builder.build().unwrap();
        assert_eq!(scene.names(), ["a", "b"]);
        let objects: Vec<_> = scene
            .objects()
            .iter()
            .map(|o| (o.name.as_str(), o.pose))
            .collect();
        assert_eq!(objects, [("a", Pose::identity()), ("b", far)]);
        assert_eq!(
            ["a", "b", "c"].map(|n| scene.object_id(n)),
            [Some(0), Some(1), None]
        );
        assert!(!scene.is_naive());
        scene.set_naive(true);
        assert!(scene.is_naive());
        scene.set_naive(false);
        assert!(!scene.is_naive());
        scene.step(&Frame::new()).unwrap();
        let touching = scene
            .step(Frame::new().set(1, Pose::identity()))
            .unwrap()
            .clone();
        assert_eq!(touching.pairs.len(), 1);
        assert_eq!(scene.report(), &touching);
        assert_eq!(scene.summary().frames, 2);
        // Each step adds its own (positive) time.
        assert!(scene.summary().seconds > 0.0);
    }
}
