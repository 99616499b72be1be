//! What storing a mesh cost in precision: the check behind `build`'s warning that the
//! stored coordinates are coarse for the model's size.
//!
//! A file stores every vertex rounded once (to f32 by default). Rounding is relative to a
//! coordinate's magnitude, so a model far from its origin (a part in millimetres placed in
//! an assembly, a scan in survey coordinates) loses detail in proportion to its distance
//! from the origin over its size; small triangles can even collapse to zero area. Queries
//! are exact for the stored model, so nothing fails: the answers are those of a coarser
//! model than the user drew. Centring (or f64) keeps the detail.

use crate::arr3::{norm2, sub};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::mesh::{triangle_is_degenerate, TriMesh};
use crate::real::Precision;
use crate::tree::TreeView;
use std::fmt;

/// Rounding per coordinate above this share of the model's bounding-box diagonal is
/// reported: far above what f32 costs a model centred near its origin (a few 1e-8 of its
/// size), reached by a model a few hundred of its sizes from its origin.
pub const REPORTED_ROUNDING: f64 = 1e-5;

/// What storing a mesh's vertices cost ([`rounding_loss`]), when it is worth a warning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundingLoss {
    /// Triangles of non-zero area in the input that have zero area as stored.
    pub collapsed: usize,
    /// The largest magnitude of a stored coordinate, stored units.
    pub largest_coordinate: f64,
    /// The most storing moved a coordinate of that magnitude (half a unit in the last
    /// place of the stored precision; 0 where the stored values are the input's, an f64
    /// file without a placement), stored units.
    pub rounding: f64,
    /// The stored model's bounding-box diagonal, stored units.
    pub size: f64,
    /// The stored precision.
    pub precision: Precision,
}

impl RoundingLoss {
    /// How to keep the detail, in one clause, with the two remedies spelled as the caller
    /// takes them (`"--center"` and `"--precision f64"` on the command line): centring
    /// where the coordinates reach beyond the model's size (the model lies off its
    /// origin), f64 for an f32 file. `None` where neither would help.
    pub fn remedy(&self, center: &str, f64: &str) -> Option<String> {
        let off_origin = self.largest_coordinate > self.size;
        let in_f32 = self.precision == Precision::F32;
        let how = match (off_origin, in_f32) {
            (true, true) => format!("{center} or {f64}"),
            (true, false) => center.to_owned(),
            (false, true) => f64.to_owned(),
            (false, false) => return None,
        };
        Some(format!("build with {how} to keep the detail"))
    }

    /// The whole warning, one line: what was lost, then [`RoundingLoss::remedy`] where
    /// one would help, its options spelled as the caller takes them.
    pub fn warning(&self, center: &str, f64: &str) -> String {
        match self.remedy(center, f64) {
            Some(how) => format!("{self}: {how}"),
            None => self.to_string(),
        }
    }
}

/// What building `file` from `mesh` cost in precision, if it is worth telling: some
/// triangles collapsed to zero area, or storing moved coordinates by more than
/// [`REPORTED_ROUNDING`] of the model's size. `None` otherwise, and for a model of no size.
/// (A file whose triangles cannot be read, which [`crate::build::build`] never makes,
/// counts none as collapsed.)
///
/// # Examples
///
/// ```
/// use obbtree::build::{build, rounding_loss, BuildOptions};
/// use obbtree::mesh::TriMesh;
///
/// // A triangle of unit size ten thousand of its sizes from the origin, stored in f32.
/// let mesh = TriMesh::new(
///     vec![[1e4, 0.0, 0.0], [1e4 + 1.0, 0.0, 0.0], [1e4, 1.0, 0.0]],
///     vec![[0, 1, 2]],
/// )?;
/// let file = build(&mesh, &BuildOptions::default(), None)?;
/// let loss = rounding_loss(&mesh, &file).expect("coarse for its size");
/// assert_eq!(loss.collapsed, 0);
/// assert!(loss.rounding > 1e-5 * loss.size);
/// assert_eq!(
///     loss.remedy("--center", "--precision f64").as_deref(),
///     Some("build with --center or --precision f64 to keep the detail")
/// );
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn rounding_loss(mesh: &TriMesh, file: &ObbtFile) -> Option<RoundingLoss> {
    let info = file.info();
    let (lo, hi) = (info.stats.bounds_min, info.stats.bounds_max);
    let size = norm2(sub(hi, lo)).sqrt();
    let largest_coordinate = lo.iter().chain(&hi).fold(0.0_f64, |m, x| m.max(x.abs()));
    let exact = info.precision == Precision::F64 && info.placement.is_identity();
    let rounding = if exact {
        0.0
    } else {
        half_ulp(info.precision, largest_coordinate)
    };
    // (Only a file with triangles of no area can have collapsed any: most builds skip the
    // pass.)
    let collapsed = if info.stats.degenerate_triangles == 0 {
        0
    } else {
        file.visit(Collapsed { mesh }).unwrap_or(0)
    };
    let coarse = rounding > REPORTED_ROUNDING * size;
    // (A non-finite size is no model to speak of.)
    ((collapsed > 0 || coarse) && size.is_finite() && size > 0.0).then_some(RoundingLoss {
        collapsed,
        largest_coordinate,
        rounding,
        size,
        precision: info.precision,
    })
}

/// Counts the stored triangles of zero area whose input triangle has an area: face by
/// face, so that an input triangle of zero area that rounding gives an area does not
/// cancel one that rounding collapsed.
struct Collapsed<'m> {
    mesh: &'m TriMesh,
}

impl TreeVisitor for Collapsed<'_> {
    type Output = usize;
    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> usize {
        let (vertices, faces) = (self.mesh.vertices(), self.mesh.faces());
        let input_has_area = |id: u32| {
            let corners = faces
                .get(id as usize)?
                .map(|v| vertices.get(v as usize).copied());
            let [Some(a), Some(b), Some(c)] = corners else {
                return None;
            };
            Some(!triangle_is_degenerate(a, b, c))
        };
        (0..tree.faces().len() as u32)
            .filter(|&face| {
                let stored = tree.triangle(face);
                let zero_area = stored.is_some_and(|[a, b, c]| triangle_is_degenerate(a, b, c));
                let id = tree.source_id(face);
                zero_area && id.and_then(input_has_area).unwrap_or(false)
            })
            .count()
    }
}

/// Half the unit in the last place of `x` (finite, non-negative) in `precision`: the most
/// rounding to it moves a value of that magnitude.
fn half_ulp(precision: Precision, x: f64) -> f64 {
    let ulp = match precision {
        Precision::F32 => {
            // The spacing of the f32 nearest `x` (below it at the largest f32).
            let y = x as f32;
            let up = y.next_up();
            f64::from(if up.is_finite() {
                up - y
            } else {
                y - y.next_down()
            })
        }
        Precision::F64 => {
            let up = x.next_up();
            if up.is_finite() {
                up - x
            } else {
                x - x.next_down()
            }
        }
    };
    ulp / 2.0
}

impl fmt::Display for RoundingLoss {
    /// What was lost, in one line ([`RoundingLoss::warning`] adds how to keep it).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.precision {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        };
        write!(
            f,
            "stored coordinates up to {} in {name} move by up to {:.1e}, {:.1e} of the model's size ({})",
            Short(self.largest_coordinate),
            self.rounding,
            self.rounding / self.size,
            Short(self.size)
        )?;
        if self.collapsed > 0 {
            let s = if self.collapsed == 1 { "" } else { "s" };
            write!(f, "; {} triangle{s} collapsed to zero area", self.collapsed)?;
        }
        Ok(())
    }
}

/// A number to at least four significant digits: plainly for the magnitudes of everyday
/// coordinates and sizes, in exponent form outside them.
struct Short(f64);

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if (1e-3..1e5).contains(&x.abs()) {
            // (From 1e-3 to 1e5 the exponent is -3 to 4: 6 to 0 decimals.)
            let decimals = (3 - x.abs().log10().floor() as i32).max(0) as usize;
            write!(f, "{x:.decimals$}")
        } else {
            write!(f, "{x:.3e}")
        }
    }
}
