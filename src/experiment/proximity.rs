//! Parallel close proximity (§5.3.2): a unit sphere inside a sphere of radius 1 + gap, of
//! the same tessellation, both turned at random, for gaps over many decades. No triangle
//! pair touches; what the volume types differ in is how deep they must descend to tell the
//! surfaces apart, which shows as the slope of volume tests against the gap on log-log
//! axes: about −1 for OBBs, whose thickness shrinks with the square of their size, −2 for
//! AABBs and spheres.

use super::{
    fit_line, measure, of_kind, turned_pair, Comparison, ExperimentError, Fit, Job, Outcome, Point,
    Progress, Size, Variant,
};
use crate::bv::BvKind;
use crate::generate::{lat_long_sphere, Rng};
use crate::stats::LevelStats;
use nalgebra::Vector3;

/// Runs the experiment: 40,000-triangle spheres, gaps 100 to 1e-7 in quarter decades and
/// 100 orientations each at full size; 10,000 triangles, gaps 100 to 1e-3 in quarter
/// decades and 8 orientations quick. `seed` draws the orientations.
///
/// The ideal spheres never meet, but their polyhedra do once the gap is below the depth
/// of a facet under the sphere (about 1e-4 at 40,000 triangles): the smallest gaps count
/// contacts too.
///
/// # Errors
///
/// [`ExperimentError::Generate`] or [`ExperimentError::Build`] if a sphere or its tree
/// cannot be made, [`ExperimentError::Query`] if a query fails, and
/// [`ExperimentError::Levels`] if a tree's levels cannot be measured (none happens with
/// the experiment's own parameters: these errors are bugs).
pub fn run(size: Size, seed: u64, progress: Option<&Progress>) -> Result<Outcome, ExperimentError> {
    let (stacks, slices, per_decade, decades, queries): (u32, u32, i32, i32, u32) = match size {
        Size::Full => (101, 200, 4, 9, 100),
        Size::Quick => (51, 100, 4, 5, 8),
    };
    let inner = lat_long_sphere(1.0, stacks, slices)?;
    let gaps: Vec<f64> = (0..=per_decade * decades)
        .map(|k| 10f64.powf(2.0 - f64::from(k) / f64::from(per_decade)))
        .collect();
    let outers = gaps
        .iter()
        .map(|&gap| lat_long_sphere(1.0 + gap, stacks, slices))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rng = Rng::new(seed);
    let orientations: Vec<_> = (0..queries)
        .map(|_| turned_pair(&mut rng, Vector3::zeros()))
        .collect();
    let per_kind = gaps.len() as u64 * u64::from(queries);
    Progress::plan(progress, per_kind * BvKind::ALL.len() as u64);
    let mut points = Vec::new();
    let mut levels = Vec::new();
    for bv in BvKind::ALL {
        let b = super::tree(&inner, bv, Variant::Standard)?;
        levels.push((bv, b.level_stats().map_err(ExperimentError::Levels)?));
        let trees = outers
            .iter()
            .map(|outer| super::tree(outer, bv, Variant::Standard))
            .collect::<Result<Vec<_>, _>>()?;
        let jobs: Vec<Job<'_>> = trees
            .iter()
            .zip(&gaps)
            .map(|(a, &gap)| Job {
                a,
                b: &b,
                bv,
                variant: Variant::Standard,
                x: gap,
                poses: orientations.clone(),
            })
            .collect();
        let mut measured = measure(&jobs, progress)?;
        // Smallest gap first, as the dissertation plots it.
        measured.reverse();
        points.extend(measured);
    }
    let fits: Vec<Fit> = BvKind::ALL
        .into_iter()
        .filter_map(|bv| ramp_fit(&of_kind(&points, bv), bv))
        .collect();
    let mut comparisons = compare(&points, &fits);
    comparisons.extend(thinning(&levels));
    Ok(Outcome {
        name: "proximity",
        x_name: "gap between the spheres",
        x_column: "gap",
        points,
        fits,
        comparisons,
        levels,
    })
}

/// Where the ramp lies between the ledges, as shares of the way from the right ledge's
/// log10 volume tests (the fewest) to the left ledge's (the most). The bends into both
/// ledges are left out: the dissertation saw a steeper stretch before the left one, and
/// the trees' top levels make one before the right.
const RAMP: (f64, f64) = (0.4, 0.9);

/// The line through the ramp of one volume type's points (log10 of volume tests against
/// log10 of the gap): the points between the two ledges, from 40% to 90% of the way in
/// log10 volume tests from the right ledge to the left one.
pub fn ramp_fit(points: &[Point], bv: BvKind) -> Option<Fit> {
    let logs = points.iter().map(|p| p.bv_tests().log10());
    let (least, most) = logs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    let (from, to) = (
        least + RAMP.0 * (most - least),
        least + RAMP.1 * (most - least),
    );
    let ramp: Vec<&Point> = points
        .iter()
        .filter(|p| (from..=to).contains(&p.bv_tests().log10()))
        .collect();
    let logs: Vec<(f64, f64)> = ramp
        .iter()
        .map(|p| (p.x.log10(), p.bv_tests().log10()))
        .collect();
    let line = fit_line(&logs)?;
    let xs = ramp.iter().map(|p| p.x);
    let (from, to) = xs.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    Some(Fit {
        bv,
        measure: "bv_tests",
        line,
        from,
        to,
    })
}

/// The deepest level whose nodes are all internal (level `l` of a binary tree holds
/// `2^l` nodes until leaves appear): below it, single-triangle leaves of no thickness
/// skew the mean, as the dissertation notes of Fig. 5.17.
pub fn last_full_level(levels: &[LevelStats]) -> Option<usize> {
    let full = |(l, s): &(usize, &LevelStats)| {
        u32::try_from(*l).ok().and_then(|l| 2u64.checked_pow(l)) == Some(s.nodes)
    };
    let last = levels.iter().enumerate().take_while(full).last()?.0;
    // The last full level's nodes may have leaves as children.
    last.checked_sub(1)
}

/// How much the inner sphere's mean volume thickness shrinks over two levels, as a
/// geometric mean from level 2 to [`last_full_level`] (Fig. 5.17: OBBs 4x, the rate
/// that gives slope −1; AABBs and spheres shrink only as their diameter does, 2x).
fn thinning(levels: &[(BvKind, Vec<LevelStats>)]) -> Vec<Comparison> {
    levels
        .iter()
        .map(|(bv, stats)| {
            let thickness = |l: usize| stats.get(l).map(|s| s.thickness.0);
            let last = last_full_level(stats).filter(|&l| l > 2);
            let measured = match (thickness(2), last.and_then(thickness), last) {
                (Some(top), Some(bottom), Some(last)) if bottom > 0.0 => {
                    format!(
                        "{:.2} (levels 2 to {last})",
                        (top / bottom).powf(2.0 / (last as f64 - 2.0))
                    )
                }
                _ => "-".into(),
            };
            Comparison::new(
                &format!(
                    "{} mean thickness shrink per two levels",
                    bv.name().to_uppercase()
                ),
                if *bv == BvKind::Obb {
                    "4"
                } else {
                    "2 (as the diameter)"
                },
                measured,
            )
        })
        .collect()
}

fn compare(points: &[Point], fits: &[Fit]) -> Vec<Comparison> {
    let mut out = Vec::new();
    for (bv, dissertation) in [
        (BvKind::Obb, "-1.14"),
        (BvKind::Aabb, "about -2"),
        (BvKind::Sphere, "about -2"),
    ] {
        let fit = fits.iter().find(|f| f.bv == bv);
        out.push(Comparison::new(
            &format!(
                "{} ramp slope (log volume tests / log gap)",
                bv.name().to_uppercase()
            ),
            dissertation,
            fit.map_or("no ramp".into(), |f| {
                format!("{:.2} (gaps {:.0e} to {:.0e})", f.line.slope, f.from, f.to)
            }),
        ));
    }
    let obb = of_kind(points, BvKind::Obb);
    let right = obb
        .iter()
        .map(Point::bv_tests)
        .fold(f64::INFINITY, f64::min);
    out.push(Comparison::new(
        "OBB right ledge (fewest volume tests, largest gaps)",
        "15",
        format!("{right:.1}"),
    ));
    let crossing = obb
        .iter()
        .filter(|p| p.contacts > 0.0)
        .map(|p| p.x)
        .fold(0.0f64, f64::max);
    out.push(Comparison::new(
        "largest gap at which the polyhedra cross",
        "not reported",
        if crossing > 0.0 {
            format!("{crossing:.1e}")
        } else {
            "none".into()
        },
    ));
    out
}
