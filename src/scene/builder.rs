//! Describing a scene in code: objects and rules collected, then checked into a [`Scene`].

use super::error::SceneError;
use super::object::SceneObject;
use super::report::ObjectId;
use super::rules::{Effect, Rule};
use super::simulate::Scene;
use crate::format::ObbtFile;
use crate::query::Pose;
use rustc_hash::FxHashMap;
use std::sync::Arc;

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
    /// As a located error: `rule 3, field a: ...` in `origin`, at `line` when known.
    pub(crate) fn located(self, origin: &str, line: Option<usize>) -> SceneError {
        let item = match self.item {
            Item::Object(k) => format!("object {}, field {}", k + 1, self.field),
            Item::Rule(k) => format!("rule {}, field {}", k + 1, self.field),
        };
        let e = SceneError::new(origin, self.message).in_field(item);
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
    ///
    /// # Errors
    ///
    /// A [`SceneError`] with origin `scene`, naming the object or rule and field at fault:
    /// an object or group name that is empty or not made of ASCII letters, digits, `_`,
    /// `.` and `-`; an object name used twice; assets of different volume types or
    /// precisions; a rule whose selector names no object or group; or an effect with a
    /// clearance, relative error or maximum distance out of range.
    ///
    /// # Examples
    ///
    /// See the [module example](super) for a scene built and stepped. A rule about an
    /// object that does not exist is refused:
    ///
    /// ```
    /// use obbtree::format::ObbtFile;
    /// use obbtree::query::Pose;
    /// use obbtree::scene::{Effect, SceneBuilder};
    /// use std::sync::Arc;
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let table = Arc::new(ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?);
    /// let mut scene = SceneBuilder::new();
    /// scene.object("table", table, &[], Pose::identity());
    /// scene.rule("table", "chair", Effect::Contact);
    /// let error = scene.build().unwrap_err();
    /// assert_eq!(error.origin, "scene");
    /// # Ok(())
    /// # }
    /// ```
    pub fn build(self) -> Result<Scene, SceneError> {
        self.checked().map_err(|p| p.located("scene", None))
    }

    /// Checks the description and builds the scene, or says which item and field is wrong
    /// (for the file reader to locate).
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
        // One node type (volume, precision, layout) for the whole scene.
        if let Some(first) = self.objects.first() {
            let kind = |o: &SceneObject| o.asset.node_type();
            if let Some((k, other)) = self
                .objects
                .iter()
                .enumerate()
                .find(|(_, o)| kind(o) != kind(first))
            {
                let describe = |o: &SceneObject| o.asset.node_type().to_string();
                let m = format!(
                    "object {:?} stores {} but {:?} stores {}; a scene's assets share one volume type, precision and layout",
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
