//! The work every query reports (dissertation §2.5.1): volume and triangle tests, node pairs.

/// Work done by one query.
///
/// For binary trees with single-face leaves and a traversal that runs to completion,
/// `1 = D − I + 2S + 2K` (§2.5.1): every overlapping internal pair spawns two pair tests and
/// every overlapping leaf pair one triangle test.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// D: bounding-volume pair tests that pruned the pair (disjoint, or too far / too near
    /// to matter for a distance or span query).
    pub bv_disjoint: u64,
    /// I: bounding-volume pair tests that did not prune.
    pub bv_overlap: u64,
    /// S: triangle pair tests whose triangles do not touch.
    pub tri_separated: u64,
    /// K: triangle pair tests whose triangles touch.
    pub tri_contact: u64,
    /// Node pairs a traversal decided on: taken off its stack or heap, each reading one
    /// node of each tree. When a distance or span traversal ends because the smallest key
    /// waiting is pruned, the pairs still waiting count here and in D (each was tested when
    /// it was pushed), so `D + I` stays the number of pair tests and the identity holds.
    pub nodes_visited: u64,
}

impl Work {
    /// Bounding-volume pair tests, `D + I`.
    pub fn bv_tests(&self) -> u64 {
        self.bv_disjoint + self.bv_overlap
    }

    /// Triangle pair tests, `S + K`.
    pub fn tri_tests(&self) -> u64 {
        self.tri_separated + self.tri_contact
    }

    /// `D − I + 2S + 2K`, which is 1 for a complete traversal of binary single-face trees.
    pub fn identity_value(&self) -> i128 {
        i128::from(self.bv_disjoint) - i128::from(self.bv_overlap)
            + 2 * i128::from(self.tri_separated)
            + 2 * i128::from(self.tri_contact)
    }
}

/// Work summed: what several searches did together.
impl std::ops::AddAssign for Work {
    fn add_assign(&mut self, other: Work) {
        self.bv_disjoint += other.bv_disjoint;
        self.bv_overlap += other.bv_overlap;
        self.tri_separated += other.tri_separated;
        self.tri_contact += other.tri_contact;
        self.nodes_visited += other.nodes_visited;
    }
}

#[cfg(test)]
mod tests {
    use super::Work;

    /// The sums and the identity's value on counts that are all different (and none 0 or
    /// 2, so that doubling by a product would show), so that no term can stand in for
    /// another; the identity is 1 only for complete traversals.
    #[test]
    fn the_sums_and_the_identity_add_their_own_terms() {
        let w = Work {
            bv_disjoint: 13,
            bv_overlap: 3,
            tri_separated: 5,
            tri_contact: 7,
            nodes_visited: 11,
        };
        assert_eq!((w.bv_tests(), w.tri_tests()), (16, 12));
        assert_eq!(w.identity_value(), 13 - 3 + 2 * 5 + 2 * 7);
        let mut twice = w;
        twice += w;
        let expected = Work {
            bv_disjoint: 26,
            bv_overlap: 6,
            tri_separated: 10,
            tri_contact: 14,
            nodes_visited: 22,
        };
        assert_eq!(twice, expected);
    }
}
