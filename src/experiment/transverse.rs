//! Transverse contact as the tessellation grows (§5.3.3.1): two unit spheres whose
//! centres are √2 apart meet at right angles along a circle; both are turned at
//! random for every query. Contacts and volume tests both grow as the square root of the
//! triangle count, as the lower bound of §2.6.3 does: every volume type is within a
//! constant factor of optimal here.

use super::{
    fit_line, measure, of_kind, turned_pair, Comparison, ExperimentError, Fit, Job, Outcome, Point,
    Progress, Size, Variant,
};
use crate::bv::BvKind;
use crate::generate::{lat_long_sphere, Rng};
use nalgebra::Vector3;

/// The distance between the centres: √2, where unit spheres meet at right angles (the
/// dissertation's 1.41421).
const OFFSET: f64 = std::f64::consts::SQRT_2;

/// The smallest triangle count a fit takes: coarser spheres are far from round.
const FIT_FROM: f64 = 500.0;

/// Runs the experiment: spheres of 80 to about 600,000 triangles (stacks 5 to 388, twice
/// as many slices) with 1,000 queries each at full size (200 from 100,000 triangles);
/// 80 to 6,240 triangles with 20 queries quick. `seed` draws the orientations.
///
/// # Errors
///
/// [`ExperimentError::Generate`] or [`ExperimentError::Build`] if a sphere or its tree
/// cannot be made, and [`ExperimentError::Query`] if a query fails (none happens with
/// the experiment's own parameters: these errors are bugs).
pub fn run(size: Size, seed: u64, progress: Option<&Progress>) -> Result<Outcome, ExperimentError> {
    let (stacks, queries): (&[u32], u32) = match size {
        Size::Full => (
            &[5, 7, 10, 14, 20, 28, 40, 57, 80, 113, 160, 226, 320, 388],
            1000,
        ),
        Size::Quick => (&[5, 7, 10, 14, 20, 28, 40], 20),
    };
    let meshes = stacks
        .iter()
        .map(|&s| lat_long_sphere(1.0, s, 2 * s))
        .collect::<Result<Vec<_>, _>>()?;
    // The same orientations for every volume type, so their contacts agree pose by pose.
    let mut rng = Rng::new(seed);
    let poses: Vec<Vec<_>> = meshes
        .iter()
        .map(|mesh| {
            let count = if mesh.faces().len() >= 100_000 {
                queries.min(200)
            } else {
                queries
            };
            (0..count)
                .map(|_| turned_pair(&mut rng, Vector3::new(OFFSET, 0.0, 0.0)))
                .collect()
        })
        .collect();
    let per_kind: usize = poses.iter().map(Vec::len).sum();
    Progress::plan(progress, (per_kind * BvKind::ALL.len()) as u64);
    let mut points = Vec::new();
    for bv in BvKind::ALL {
        let trees = meshes
            .iter()
            .map(|mesh| super::tree(mesh, bv, Variant::Standard))
            .collect::<Result<Vec<_>, _>>()?;
        let jobs: Vec<Job<'_>> = trees
            .iter()
            .zip(&meshes)
            .zip(&poses)
            .map(|((tree, mesh), poses)| Job {
                a: tree,
                b: tree,
                bv,
                variant: Variant::Standard,
                x: mesh.faces().len() as f64,
                poses: poses.clone(),
            })
            .collect();
        points.extend(measure(&jobs, progress)?);
    }
    let mut fits = Vec::new();
    for bv in BvKind::ALL {
        let series = of_kind(&points, bv);
        for (measure, value) in [
            ("contacts", (|p: &Point| p.contacts) as fn(&Point) -> f64),
            ("bv_tests", Point::bv_tests),
        ] {
            if let Some(fit) = power_fit(&series, bv, measure, value) {
                fits.push(fit);
            }
        }
    }
    let comparisons = compare(&points, &fits);
    Ok(Outcome {
        name: "transverse",
        x_name: "triangles per sphere",
        x_column: "triangles",
        points,
        fits,
        comparisons,
        levels: Vec::new(),
    })
}

/// The power law `value ∝ n^slope` fitted over the points from [`FIT_FROM`] triangles.
fn power_fit(
    series: &[Point],
    bv: BvKind,
    measure: &'static str,
    value: fn(&Point) -> f64,
) -> Option<Fit> {
    let kept: Vec<&Point> = series
        .iter()
        .filter(|p| p.x >= FIT_FROM && value(p) > 0.0)
        .collect();
    let logs: Vec<(f64, f64)> = kept
        .iter()
        .map(|p| (p.x.log10(), value(p).log10()))
        .collect();
    let line = fit_line(&logs)?;
    Some(Fit {
        bv,
        measure,
        line,
        from: kept.first()?.x,
        to: kept.last()?.x,
    })
}

fn compare(points: &[Point], fits: &[Fit]) -> Vec<Comparison> {
    let mut out = Vec::new();
    for measure in ["contacts", "bv_tests"] {
        for bv in BvKind::ALL {
            let fit = fits.iter().find(|f| f.bv == bv && f.measure == measure);
            out.push(Comparison::new(
                &format!(
                    "{} {} growth (exponent of triangles)",
                    bv.name().to_uppercase(),
                    if measure == "contacts" {
                        "contacts"
                    } else {
                        "volume tests"
                    }
                ),
                "1/2",
                fit.map_or("-".into(), |f| format!("{:.2}", f.line.slope)),
            ));
        }
    }
    let below = points
        .iter()
        .filter(|p| p.bv_tests() + 1e-9 < p.lower_bound)
        .count();
    out.push(Comparison::new(
        "points (every volume type) below the least number of volume tests (§2.6.3)",
        "none can be",
        format!("{below} of {}", points.len()),
    ));
    out
}
