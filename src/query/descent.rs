//! Which tree to descend when both nodes of a pair are internal (dissertation §7.3.2).

use crate::bv::BoundingVolume;

/// The descent rule of a tandem traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DescentRule {
    /// Descend the node with the larger diameter (the default: it shrinks the larger volume,
    /// which is what keeps pair tests failing early).
    #[default]
    LargestDiameter,
    /// Descend the node with the larger volume.
    LargestVolume,
    /// Descend the node with the larger surface area.
    LargestArea,
    /// Always descend A while it has children, then B.
    AlwaysA,
    /// Always descend B while it has children, then A.
    AlwaysB,
}

impl DescentRule {
    /// All rules, default first.
    pub const ALL: [DescentRule; 5] = [
        DescentRule::LargestDiameter,
        DescentRule::LargestVolume,
        DescentRule::LargestArea,
        DescentRule::AlwaysA,
        DescentRule::AlwaysB,
    ];

    /// Whether to descend A (`true`) or B, when both can be descended.
    #[inline]
    pub fn descend_a<B: BoundingVolume>(self, a: &B, b: &B) -> bool {
        match self {
            DescentRule::LargestDiameter => a.diameter() >= b.diameter(),
            DescentRule::LargestVolume => a.volume() >= b.volume(),
            DescentRule::LargestArea => a.surface_area() >= b.surface_area(),
            DescentRule::AlwaysA => true,
            DescentRule::AlwaysB => false,
        }
    }

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            DescentRule::LargestDiameter => "diameter",
            DescentRule::LargestVolume => "volume",
            DescentRule::LargestArea => "area",
            DescentRule::AlwaysA => "a",
            DescentRule::AlwaysB => "b",
        }
    }
}
