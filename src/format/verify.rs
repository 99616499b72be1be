//! The O(n) checks of `verify`: after them every byte of the file is covered by some check
//! (header and directory by the header CRC, sections by their CRCs, the rest must be zero),
//! and the tree is well formed: queries terminate and volumes contain what they claim to.

use super::error::VerifyError;
use super::layout::SECTION_ALIGN;
use super::open::{ObbtFile, TreeVisitor};
use crate::bv::BoundingVolume;
use crate::placement::Placement;
use crate::real::point_to_f64;
use crate::stats::{TreeShape, TreeStats};
use crate::tree::{NodeDefect, NodeKind, TreeView};

/// The byte range `offset .. offset + length` as indices into a buffer, if it fits one.
fn byte_range(offset: u64, length: u64) -> Option<std::ops::Range<usize>> {
    let start = usize::try_from(offset).ok()?;
    let end = usize::try_from(offset.checked_add(length)?).ok()?;
    Some(start..end)
}

pub(crate) fn verify(file: &ObbtFile) -> Result<(), VerifyError> {
    let bytes = file.bytes();
    check_padding(file, bytes)?;
    for (i, s) in file.sections().iter().enumerate() {
        let data = byte_range(s.offset, s.length)
            .and_then(|range| bytes.get(range))
            .ok_or_else(|| VerifyError::new(format!("section {}", s.name()), "out of bounds"))?;
        let crc = crc32fast::hash(data);
        if crc != s.crc32 {
            return Err(VerifyError::new(
                format!("section {} (directory entry {i})", s.name()),
                format!(
                    "checksum mismatch: stored {:#010x}, computed {crc:#010x}",
                    s.crc32
                ),
            ));
        }
    }
    check_placement(file.placement())?;
    file.visit(Contents { file })
        .map_err(|e| VerifyError::new("header", e.to_string()))?
}

/// The placement (identity when the file has none) must be one a build can apply: a finite
/// scale above 0 and a finite offset.
fn check_placement(placement: Placement) -> Result<(), VerifyError> {
    let bad = |problem: String| VerifyError::new("section placement", problem);
    if !Placement::is_valid_scale(placement.scale) {
        return Err(bad(format!(
            "scale {} is not a finite number greater than 0",
            placement.scale
        )));
    }
    if placement.offset.iter().any(|c| !c.is_finite()) {
        return Err(bad(format!("offset {:?} is not finite", placement.offset)));
    }
    Ok(())
}

/// Every byte outside the header, directory and sections must be zero, so that no byte of a
/// file can change without some check noticing.
fn check_padding(file: &ObbtFile, bytes: &[u8]) -> Result<(), VerifyError> {
    let mut spans: Vec<(u64, u64)> = file
        .sections()
        .iter()
        // `open` checked that every section lies inside the file, so this cannot saturate.
        .map(|s| (s.offset, s.offset.saturating_add(s.length)))
        .collect();
    spans.sort_unstable();
    let mut cursor = u64::from(file.header().header_bytes.get());
    for (start, end) in spans
        .into_iter()
        .chain([(bytes.len() as u64, bytes.len() as u64)])
    {
        let gap = byte_range(cursor, start.saturating_sub(cursor))
            .and_then(|range| bytes.get(range))
            .unwrap_or(&[]);
        if let Some(k) = gap.iter().position(|&b| b != 0) {
            return Err(VerifyError::new(
                "padding",
                format!("byte {} is not zero", cursor.saturating_add(k as u64)),
            ));
        }
        let padding = start.saturating_sub(cursor);
        if padding >= SECTION_ALIGN {
            return Err(VerifyError::new(
                "padding",
                format!("{padding} bytes of padding at {cursor}"),
            ));
        }
        cursor = cursor.max(end);
    }
    Ok(())
}

struct Contents<'f> {
    file: &'f ObbtFile,
}

impl TreeVisitor for Contents<'_> {
    type Output = Result<(), VerifyError>;

    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Result<(), VerifyError> {
        let info = self.file.info();
        let positions: Vec<[f64; 3]> = tree.vertices().iter().map(point_to_f64).collect();
        if let Some(i) = positions
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return Err(VerifyError::new(
                "section vertices",
                format!("vertex {i} is not finite"),
            ));
        }
        let n_vertices = positions.len();
        for (i, f) in tree.faces().iter().enumerate() {
            if let Some(v) = f.iter().find(|&&v| v as usize >= n_vertices) {
                return Err(VerifyError::new(
                    "section faces",
                    format!("face {i} uses vertex {v}, but there are {n_vertices}"),
                ));
            }
        }
        let n_faces = tree.faces().len();
        let mut seen = vec![false; n_faces];
        for (i, &id) in tree.source_ids().iter().enumerate() {
            match seen.get_mut(id as usize) {
                None => {
                    return Err(VerifyError::new(
                        "section source_ids",
                        format!("entry {i} is {id}, but there are {n_faces} triangles"),
                    ))
                }
                Some(true) => {
                    return Err(VerifyError::new(
                        "section source_ids",
                        format!("entry {i} repeats id {id}"),
                    ));
                }
                Some(s) => *s = true,
            }
        }
        let shape = check_nodes(&tree, &positions, info.leaf_size)?;

        // Every face index was checked against `positions` above.
        let (stored, actual) = (info.stats, TreeStats::new(shape, &positions, tree.faces()));
        let claims = [
            ("leaves", stored.shape.leaves, actual.shape.leaves),
            ("depth", stored.shape.depth, actual.shape.depth),
            (
                "max_leaf_faces",
                stored.shape.max_leaf_faces,
                actual.shape.max_leaf_faces,
            ),
            (
                "degenerate_triangles",
                stored.degenerate_triangles,
                actual.degenerate_triangles,
            ),
        ];
        for (name, stored, actual) in claims {
            if stored != actual {
                return Err(VerifyError::new(
                    "header",
                    format!("{name} is {stored}, but the tree has {actual}"),
                ));
            }
        }
        if (stored.bounds_min, stored.bounds_max) != (actual.bounds_min, actual.bounds_max) {
            return Err(VerifyError::new(
                "header",
                "model bounds differ from the vertices' extent",
            ));
        }
        Ok(())
    }
}

/// Structure and geometry of the nodes: references in bounds and pointing forward (so every
/// traversal terminates), each node below exactly one parent, leaves partitioning the faces,
/// volumes well formed and containing every vertex of every face below them. Returns the
/// tree's shape, counted on the way for the header's claims.
fn check_nodes<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    positions: &[[f64; 3]],
    leaf_size: u32,
) -> Result<TreeShape, VerifyError> {
    let nodes = tree.nodes();
    let n_faces = tree.faces().len();
    let bad = |i: usize, problem: String| {
        VerifyError::new("section nodes", format!("node {i}: {problem}"))
    };
    let mut parent = vec![u32::MAX; nodes.len()];
    // Nodes on the path from the root, the root at 1; final when the node is reached, like
    // `parent`.
    let mut depth = vec![1u32; nodes.len()];
    let mut shape = TreeShape::default();
    let mut face_owner = vec![u32::MAX; tree.faces().len()];
    for (i, node) in nodes.iter().enumerate() {
        // Parents come first, so a node's entry is final when it is reached.
        if i > 0 && parent.get(i).is_none_or(|&p| p == u32::MAX) {
            return Err(bad(i, "no parent references it".into()));
        }
        // Fewer than `u32::MAX` nodes (the header counts them in a `u32`), so the index
        // never collides with the `u32::MAX` marker.
        let index = u32::try_from(i).map_err(|_| bad(i, "index exceeds u32".into()))?;
        node.bv.validate().map_err(|d| bad(i, d.to_string()))?;
        let node_depth = depth.get(i).copied().unwrap_or(u32::MAX);
        // The references are checked by the decoder the queries use; the raw range only
        // words the message.
        let kind = tree.node_kind(index).map_err(|defect| {
            let range = tree.node_ref(node).range();
            let (start, end) = (range.start, range.end);
            bad(
                i,
                match defect {
                    NodeDefect::BadChildren => format!(
                        "children {start}..{end} are not after it and below {}",
                        nodes.len()
                    ),
                    NodeDefect::BadFaces => {
                        format!("faces {start}..{end} exceed the {n_faces} faces")
                    }
                    NodeDefect::Missing => defect.to_string(),
                },
            )
        })?;
        match kind {
            NodeKind::Children(children) => {
                for c in children {
                    // In bounds: `node_kind` checked the range against the node array.
                    let (Some(slot), Some(d)) =
                        (parent.get_mut(c as usize), depth.get_mut(c as usize))
                    else {
                        return Err(bad(i, format!("child {c} is out of bounds")));
                    };
                    if *slot != u32::MAX {
                        return Err(bad(i, format!("child {c} already has parent {}", *slot)));
                    }
                    *slot = index;
                    *d = node_depth.saturating_add(1);
                }
            }
            NodeKind::Faces(faces) => {
                let count = faces.len();
                if count > leaf_size as usize {
                    return Err(bad(
                        i,
                        format!("{count} faces exceed the leaf size {leaf_size}"),
                    ));
                }
                shape.leaf(node_depth, u32::try_from(count).unwrap_or(u32::MAX));
                for f in faces {
                    // In bounds: `node_kind` checked the range against the face array.
                    let Some(owner) = face_owner.get_mut(f as usize) else {
                        return Err(bad(i, format!("face {f} is out of bounds")));
                    };
                    if *owner != u32::MAX {
                        return Err(bad(i, format!("face {f} is also in leaf {}", *owner)));
                    }
                    *owner = index;
                }
            }
        }
    }
    if let Some(f) = face_owner.iter().position(|&o| o == u32::MAX) {
        return Err(VerifyError::new(
            "section nodes",
            format!("face {f} is in no leaf"),
        ));
    }
    // Containment: each face's corners inside its leaf and every ancestor. The tolerance only
    // absorbs the f64 arithmetic of this check; the builder rounds volumes outward.
    let scale = positions
        .iter()
        .flatten()
        .fold(1.0f64, |m, c| m.max(c.abs()));
    let tolerance = 1e-12 * scale;
    // Every index below was checked above (vertex indices in `visit`, face ranges and
    // parents here); a failed lookup is reported rather than trusted.
    let unchecked = |what: &str| VerifyError::new("section nodes", format!("{what} out of bounds"));
    for (f, (&leaf, face)) in face_owner.iter().zip(tree.faces()).enumerate() {
        let [Some(&p), Some(&q), Some(&r)] = face.map(|v| positions.get(v as usize)) else {
            return Err(unchecked("vertex index"));
        };
        let corners = [p, q, r];
        let mut at = leaf;
        loop {
            let node = nodes
                .get(at as usize)
                .ok_or_else(|| unchecked("leaf or parent"))?;
            if let Some((k, (_, vertex))) = corners
                .iter()
                .zip(face)
                .enumerate()
                .find(|(_, (&p, _))| !node.bv.contains(p, tolerance))
            {
                return Err(bad(
                    at as usize,
                    format!("volume does not contain corner {k} of face {f} (vertex {vertex})"),
                ));
            }
            if at == 0 {
                break;
            }
            at = *parent.get(at as usize).ok_or_else(|| unchecked("parent"))?;
        }
    }
    Ok(shape)
}
