//! What storing a mesh cost in precision: the check behind `build`'s warning that the
//! stored coordinates are coarse for the model's size.
//!
//! A file stores every vertex rounded once (to f32 by default). Rounding is relative to a
//! coordinate's magnitude, so a model far from its origin (a part in millimetres placed in
//! an assembly, a scan in survey coordinates) loses detail in proportion to its distance
//! from the origin over its size; small triangles can even collapse to zero area. Queries
//! are exact for the stored model, so nothing fails: the answers are those of a coarser
//! model than the user drew. `--center` (or f64) keeps the detail.

use crate::arr3::{norm2, sub};
use crate::format::ObbtFile;
use crate::mesh::TriMesh;
use crate::real::Precision;
use std::fmt;

/// Rounding per coordinate above this share of the model's bounding-box diagonal is
/// reported: well above what f32 costs a model near its origin (about 6e-8 of its size),
/// and where a model lies a thousand sizes or more from its origin.
pub const REPORTED_ROUNDING: f64 = 1e-5;

/// What storing a mesh's vertices cost ([`rounding_loss`]), when it is worth a warning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundingLoss {
    /// Triangles of non-zero area in the input that have zero area as stored.
    pub collapsed: usize,
    /// The largest magnitude of a stored coordinate, stored units.
    pub largest_coordinate: f64,
    /// The most the stored precision moves a coordinate of that magnitude (half its unit
    /// in the last place), stored units.
    pub rounding: f64,
    /// The stored model's bounding-box diagonal, stored units.
    pub size: f64,
    /// The stored precision.
    pub precision: Precision,
}

/// What building `file` from `mesh` cost in precision, if it is worth telling: some
/// triangles collapsed to zero area, or the stored precision moves coordinates by more
/// than [`REPORTED_ROUNDING`] of the model's size. `None` otherwise (and for an empty
/// model).
///
/// # Examples
///
/// ```
/// use obbtree::build::{build, rounding_loss, BuildOptions};
/// use obbtree::mesh::TriMesh;
///
/// // A small triangle ten thousand of its sizes from the origin, stored in f32.
/// let far = |x: f64| [1e4 + x, 0.0, 0.0];
/// let mesh = TriMesh::new(
///     vec![far(0.0), far(1.0), [1e4, 1.0, 0.0]],
///     vec![[0, 1, 2]],
/// )?;
/// let file = build(&mesh, &BuildOptions::default(), None)?;
/// let loss = rounding_loss(&mesh, &file).expect("coarse for its size");
/// assert_eq!(loss.collapsed, 0);
/// assert!(loss.rounding > 1e-5 * loss.size);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn rounding_loss(mesh: &TriMesh, file: &ObbtFile) -> Option<RoundingLoss> {
    let info = file.info();
    let (lo, hi) = (info.stats.bounds_min, info.stats.bounds_max);
    let size = norm2(sub(hi, lo)).sqrt();
    let largest_coordinate = lo.iter().chain(&hi).fold(0.0_f64, |m, x| m.max(x.abs()));
    let rounding = half_ulp(info.precision, largest_coordinate);
    let stored = info.stats.degenerate_triangles as usize;
    let collapsed = stored.saturating_sub(mesh.degenerate_triangle_count());
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

/// Half the unit in the last place of `x` (finite, non-negative) in `precision`: the most
/// rounding to it moves a value of that magnitude.
fn half_ulp(precision: Precision, x: f64) -> f64 {
    let ulp = match precision {
        // (The spacing of the f32 nearest `x`.)
        Precision::F32 => {
            let y = x as f32;
            f64::from(y.next_up() - y)
        }
        Precision::F64 => x.next_up() - x,
    };
    ulp / 2.0
}

impl fmt::Display for RoundingLoss {
    /// What was lost, in one line (callers add how to keep it: `--center` on the command
    /// line, `center=True` in Python).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.precision {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        };
        write!(
            f,
            "coordinates up to {} stored in {name} move by up to {:.1e}, {:.1e} of the model's size ({})",
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

/// A positive number to four significant digits, without an exponent for the magnitudes
/// of coordinates and sizes.
struct Short(f64);

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let digits = 3 - self.0.abs().log10().floor().clamp(-12.0, 3.0) as i32;
        write!(f, "{:.*}", digits.max(0) as usize, self.0)
    }
}
