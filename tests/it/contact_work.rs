//! The work of first-contact queries on the bundled cow, pinned: 30 fixed poses of a turned
//! copy moved 0.1 to 0.5 model sizes, 25 of them touching. The counts are deterministic,
//! so any change of the box test or of the order a first-contact traversal takes children
//! in shows here; a deliberate improvement updates them, with the before and after in its
//! commit message.

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::query::{CollideOptions, PairQuery, Pose};

#[test]
fn first_contact_work_on_the_cow_is_pinned() {
    let cow = build(&common::cow(), &BuildOptions::default(), None).expect("builds");
    let mut pair = PairQuery::new(&cow, &cow).expect("one volume type");
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let here = Pose::identity();
    let (mut nodes, mut touching) = (0u64, 0u32);
    for k in 0..30u64 {
        let scale = [0.1, 0.2, 0.3, 0.4, 0.5][(k % 5) as usize];
        let pose = common::turned_pose(k + 1, scale);
        let r = pair.collide(&here, &pose, &first).expect("first contact");
        let (found, stats) = (r.pairs.first().copied(), r.work);
        // The answer first: a contact exactly when the all-pairs query finds one, and
        // then one of its pairs.
        let all = pair
            .collide(&here, &pose, &CollideOptions::default())
            .expect("all pairs");
        match found {
            Some(p) => assert!(all.pairs.contains(&p), "pose {k}: {p:?} is not a contact"),
            None => assert!(all.pairs.is_empty(), "pose {k}: a contact was missed"),
        }
        touching += u32::from(found.is_some());
        nodes += stats.nodes_visited;
    }
    assert_eq!(touching, 25, "poses touching");
    // With the children of each step in stored order (before the nearer was taken first):
    // 5,451 node pairs; nearer first, before boxes on the model's axes replaced fitted ones
    // where smaller: 2,063. Before nodes were split along the axis of least child volume
    // (greatest spread only): 2,649. With hulls over samples of 2,048 vertices rather
    // than 512: 2,563.
    assert_eq!(nodes, 2_608, "node pairs visited");
}
