//! The packed 32-bit references of §7.2.2: round trips at the limits, overflow refused.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::panic)]

use crate::common;

use obbtree::tree::{
    Encoding, NodeRef, BINARY_MAX_CHILD, BINARY_MAX_FACE, VARIABLE_MAX_CHILD,
    VARIABLE_MAX_CHILDREN, VARIABLE_MAX_FACE, VARIABLE_MAX_LEAF_FACES,
};

fn round_trip(encoding: Encoding, r: NodeRef) {
    let packed = encoding.encode(r).unwrap_or_else(|e| panic!("{r:?}: {e}"));
    assert_eq!(encoding.decode(packed), r, "{encoding:?} {packed:#010x}");
}

#[test]
fn binary_round_trips_at_its_limits() {
    for first in [1, 2, 1000, BINARY_MAX_CHILD - 1, BINARY_MAX_CHILD] {
        round_trip(Encoding::Binary, NodeRef::Internal { first, count: 2 });
    }
    for first in [0, 1, 12345, BINARY_MAX_FACE] {
        round_trip(Encoding::Binary, NodeRef::Leaf { first, count: 1 });
    }
    // Sign bit set means internal: the paper's k < 0.
    assert_eq!(
        Encoding::Binary
            .encode(NodeRef::Internal { first: 1, count: 2 })
            .unwrap(),
        (-1i32) as u32
    );
    assert_eq!(
        Encoding::Binary
            .encode(NodeRef::Leaf { first: 7, count: 1 })
            .unwrap(),
        7
    );
}

#[test]
fn binary_refuses_what_it_cannot_hold() {
    let refused = [
        NodeRef::Internal { first: 0, count: 2 },
        NodeRef::Internal {
            first: BINARY_MAX_CHILD + 1,
            count: 2,
        },
        NodeRef::Internal { first: 5, count: 3 },
        NodeRef::Leaf {
            first: BINARY_MAX_FACE + 1,
            count: 1,
        },
        NodeRef::Leaf { first: 0, count: 2 },
    ];
    for r in refused {
        assert!(Encoding::Binary.encode(r).is_err(), "{r:?}");
    }
}

#[test]
fn variable_round_trips_at_its_limits() {
    for first in [0, 1, VARIABLE_MAX_CHILD] {
        for count in [1, 2, VARIABLE_MAX_CHILDREN] {
            round_trip(Encoding::Variable, NodeRef::Internal { first, count });
        }
    }
    for first in [0, 1, VARIABLE_MAX_FACE] {
        for count in [1, 2, 127, VARIABLE_MAX_LEAF_FACES] {
            round_trip(Encoding::Variable, NodeRef::Leaf { first, count });
        }
    }
    assert_eq!(VARIABLE_MAX_CHILD, (1 << 25) - 1);
    assert_eq!(VARIABLE_MAX_FACE, (1 << 24) - 1);
}

#[test]
fn variable_refuses_what_it_cannot_hold() {
    let refused = [
        NodeRef::Internal {
            first: VARIABLE_MAX_CHILD + 1,
            count: 2,
        },
        NodeRef::Internal { first: 1, count: 0 },
        NodeRef::Internal {
            first: 1,
            count: VARIABLE_MAX_CHILDREN + 1,
        },
        NodeRef::Leaf {
            first: VARIABLE_MAX_FACE + 1,
            count: 1,
        },
        NodeRef::Leaf { first: 0, count: 0 },
        NodeRef::Leaf {
            first: 0,
            count: VARIABLE_MAX_LEAF_FACES + 1,
        },
    ];
    for r in refused {
        let err = Encoding::Variable.encode(r).unwrap_err();
        assert!(!err.to_string().is_empty());
    }
}

#[test]
fn every_bit_pattern_decodes_to_a_reference_that_reencodes_identically() {
    // Decoding is total (corrupt files decode to something, then get bounds-checked), and
    // the two directions are inverse wherever encoding is defined.
    let mut rng = common::rng::Rng::new(1);
    for _ in 0..100_000 {
        // The top half: xorshift's low bits are its weakest.
        let x = (rng.next_u64() >> 32) as u32;
        for enc in [Encoding::Binary, Encoding::Variable] {
            let r = enc.decode(x);
            if let Ok(again) = enc.encode(r) {
                assert_eq!(again, x);
            }
        }
    }
}
