//! Who gets what: the effects a pair of objects can ask for, the rules that assign them,
//! and the effect of any pair, looked up in constant time.

/// What a pair of objects asks for, every frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Effect {
    /// Nothing: the pair is never tested (adjacent arm links, parts of one fixture).
    None,
    /// Whether the two touch: answered by the first contact found.
    Contact,
    /// Every contacting triangle pair.
    Contacts,
    /// Whether the two come closer than `clearance` (world units), with a witness pair.
    Clearance {
        /// The clearance, > 0.
        clearance: f64,
    },
    /// The separation distance.
    Distance {
        /// Relative error allowed (0: exact).
        rel_err: f64,
        /// At this distance or more the answer is empty (the pair is not listed) and no
        /// exact value is computed.
        max_distance: Option<f64>,
    },
    /// The span: the largest distance between the two.
    Span,
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

/// How near two objects must be for an effect to need the narrow phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Reach {
    /// Never (effect `none`).
    Never,
    /// When their surfaces are closer than this (0: touching).
    Within(f64),
    /// Every frame, whatever the distance (a distance without a limit, a span).
    Always,
}

impl Effect {
    /// The scene-file name: `none`, `contact`, `contacts`, `clearance`, `distance`, `span`.
    pub fn name(&self) -> &'static str {
        match self {
            Effect::None => "none",
            Effect::Contact => "contact",
            Effect::Contacts => "contacts",
            Effect::Clearance { .. } => "clearance",
            Effect::Distance { .. } => "distance",
            Effect::Span => "span",
        }
    }

    pub(crate) fn reach(&self) -> Reach {
        match *self {
            Effect::None => Reach::Never,
            Effect::Contact | Effect::Contacts => Reach::Within(0.0),
            Effect::Clearance { clearance } => Reach::Within(clearance),
            Effect::Distance {
                max_distance: Some(limit),
                ..
            } => Reach::Within(limit),
            Effect::Distance { .. } | Effect::Span => Reach::Always,
        }
    }
}

/// For every object, which rules match it on side `a` and on side `b`, as bit sets; the
/// effect of a pair is the last rule matching it in either order.
#[derive(Clone, Debug)]
pub(crate) struct RuleTable {
    effects: Vec<Effect>,
    /// 64-bit words per object row.
    words: usize,
    side_a: Vec<u64>,
    side_b: Vec<u64>,
}

impl RuleTable {
    /// The table of `effects` (one per rule, in order) for `objects` objects, where
    /// `matches(rule, side_b, object)` says whether a rule's side matches an object.
    pub(crate) fn new(
        effects: Vec<Effect>,
        objects: usize,
        matches: impl Fn(usize, bool, usize) -> bool,
    ) -> RuleTable {
        let words = effects.len().div_ceil(64).max(1);
        let mut side_a = vec![0u64; objects.saturating_mul(words)];
        let mut side_b = side_a.clone();
        for (rows, side) in [(&mut side_a, false), (&mut side_b, true)] {
            for (object, row) in rows.chunks_exact_mut(words).enumerate() {
                for (rule, _) in effects.iter().enumerate() {
                    if matches(rule, side, object) {
                        if let Some(word) = row.get_mut(rule / 64) {
                            *word |= 1 << (rule % 64);
                        }
                    }
                }
            }
        }
        RuleTable {
            effects,
            words,
            side_a,
            side_b,
        }
    }

    fn row<'t>(&self, side: &'t [u64], object: usize) -> &'t [u64] {
        let start = object.saturating_mul(self.words);
        side.get(start..start.saturating_add(self.words))
            .unwrap_or(&[])
    }

    /// The effect of the pair `(i, j)`: the last rule whose sides match it in either order,
    /// `none` without one (and for an object with itself).
    pub(crate) fn effect(&self, i: usize, j: usize) -> Effect {
        if i == j {
            return Effect::None;
        }
        let (ai, bi) = (self.row(&self.side_a, i), self.row(&self.side_b, i));
        let (aj, bj) = (self.row(&self.side_a, j), self.row(&self.side_b, j));
        for w in (0..self.words).rev() {
            let word = |row: &[u64]| row.get(w).copied().unwrap_or(0);
            let hits = (word(ai) & word(bj)) | (word(aj) & word(bi));
            if hits != 0 {
                let rule = w * 64 + 63 - hits.leading_zeros() as usize;
                return self.effects.get(rule).copied().unwrap_or(Effect::None);
            }
        }
        Effect::None
    }

    /// The largest distance any rule matching `object` (either side) reaches within: how
    /// far its broad-phase box must be inflated, in total, for those rules.
    pub(crate) fn reach_of(&self, object: usize) -> f64 {
        let (a, b) = (
            self.row(&self.side_a, object),
            self.row(&self.side_b, object),
        );
        let mut reach = 0.0f64;
        for (rule, effect) in self.effects.iter().enumerate() {
            let bit = |row: &[u64]| {
                row.get(rule / 64)
                    .is_some_and(|w| w >> (rule % 64) & 1 == 1)
            };
            if let (true, Reach::Within(d)) = (bit(a) || bit(b), effect.reach()) {
                reach = reach.max(d);
            }
        }
        reach
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table of 130 rules (three words per row), where `rule` matches `(side, object)`.
    fn table(matches: impl Fn(usize, bool, usize) -> bool) -> RuleTable {
        let effects = (0..130)
            .map(|rule| Effect::Clearance {
                clearance: 1.0 + rule as f64,
            })
            .collect();
        RuleTable::new(effects, 4, matches)
    }

    /// The last matching rule wins, in either order of the pair and whichever word of the
    /// row holds it; an object with itself and a pair no rule matches get `none`.
    #[test]
    fn the_last_rule_matching_a_pair_in_either_order_wins() {
        // Rule r matches (a: object r % 3, b: object 3) for r in 5, 69, 70 and 100; rule
        // 129 matches a: object 1, b: object 2.
        let t = table(|rule, side_b, object| match (rule, side_b) {
            (5 | 69 | 70 | 100, false) => object == rule % 3,
            (5 | 69 | 70 | 100, true) => object == 3,
            (129, false) => object == 1,
            (129, true) => object == 2,
            _ => false,
        });
        let clearance = |c: f64| Effect::Clearance { clearance: c };
        assert_eq!(t.effect(2, 3), clearance(6.0)); // rule 5, word 0
        assert_eq!(t.effect(3, 0), clearance(70.0)); // rule 69 (b side first), word 1
        assert_eq!(t.effect(1, 3), clearance(101.0)); // rule 100 beats 70, word 1
        assert_eq!(t.effect(2, 1), clearance(130.0)); // rule 129, word 2, reversed
        assert_eq!(t.effect(1, 2), clearance(130.0));
        assert_eq!(t.effect(0, 1), Effect::None);
        assert_eq!(t.effect(3, 3), Effect::None);
        assert_eq!(t.effect(0, 2), Effect::None);
        // Out-of-range objects match nothing rather than panic.
        assert_eq!(t.effect(9, 3), Effect::None);
    }

    /// An object's reach is the largest of the rules that name it on either side, wherever
    /// the rule's bit lies in the row.
    #[test]
    fn an_objects_reach_is_the_largest_of_its_rules() {
        let t = table(|rule, side_b, object| {
            matches!(
                (rule, side_b, object),
                (3 | 65, false, 0) | (127, true, 1) | (64, true, 2)
            )
        });
        assert_eq!(t.reach_of(0), 66.0);
        assert_eq!(t.reach_of(1), 128.0);
        assert_eq!(t.reach_of(2), 65.0);
        assert_eq!(t.reach_of(3), 0.0);
        let none = RuleTable::new(vec![Effect::Span, Effect::None], 2, |_, _, _| true);
        assert_eq!(none.reach_of(0), 0.0);
        let contact = RuleTable::new(vec![Effect::Contact], 2, |_, _, _| true);
        assert_eq!(contact.effect(0, 1), Effect::Contact);
        assert_eq!(contact.reach_of(1), 0.0);
    }
}
