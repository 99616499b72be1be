//! A frame: the poses one step of a scene changes.

use super::report::ObjectId;
use crate::query::Pose;

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
