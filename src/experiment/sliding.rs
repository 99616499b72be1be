//! The sliding spheres (§5.3.1): a unit sphere at the origin, a sphere of radius 0.8
//! moving along x from 0 to 2 in steps of 0.002, both turned at random at every step, and
//! every contacting triangle pair found at each of the 1,001 positions.

use super::{
    measure, median, of_kind, of_variant, turned_pair, Comparison, ExperimentError, Job, Outcome,
    Point, Progress, Size, Variant,
};
use crate::bv::BvKind;
use crate::generate::{lat_long_sphere, Rng};
use nalgebra::Vector3;

/// Radius of the moving sphere.
const SMALL: f64 = 0.8;

/// The dissertation's setups run beside the defaults: AABBs tested as it tested them,
/// and minimal spheres.
pub const VARIANTS: [(BvKind, Variant); 2] = [
    (BvKind::Aabb, Variant::Rewrapped),
    (BvKind::Sphere, Variant::MinimalSpheres),
];

/// Runs the experiment: 40,000-triangle spheres and 1,001 positions at full size;
/// 1,600-triangle spheres and 101 positions quick. `seed` draws the orientations.
///
/// # Errors
///
/// [`ExperimentError::Generate`] or [`ExperimentError::Build`] if a sphere or its tree
/// cannot be made, and [`ExperimentError::Query`] if a query fails (none happens with
/// the experiment's own parameters: these errors are bugs).
pub fn run(size: Size, seed: u64, progress: Option<&Progress>) -> Result<Outcome, ExperimentError> {
    let (stacks, slices, steps) = match size {
        Size::Full => (101, 200, 1000u32),
        Size::Quick => (21, 40, 100),
    };
    let big = lat_long_sphere(1.0, stacks, slices)?;
    let small = lat_long_sphere(SMALL, stacks, slices)?;
    let mut rng = Rng::new(seed);
    // Offsets computed from the step index, so they are exactly those of `poses sweep`.
    let poses: Vec<(f64, _)> = (0..=steps)
        .map(|i| {
            let x = f64::from(i) * (2.0 / f64::from(steps));
            (x, turned_pair(&mut rng, Vector3::new(x, 0.0, 0.0)))
        })
        .collect();
    Progress::plan(
        progress,
        poses.len() as u64 * (BvKind::ALL.len() + VARIANTS.len()) as u64,
    );
    let mut points = Vec::new();
    let setups = BvKind::ALL
        .map(|bv| (bv, Variant::Standard))
        .into_iter()
        .chain(VARIANTS);
    for (bv, variant) in setups {
        let (a, b) = (
            super::tree(&big, bv, variant)?,
            super::tree(&small, bv, variant)?,
        );
        let jobs: Vec<Job<'_>> = poses
            .iter()
            .map(|&(x, pair)| Job {
                a: &a,
                b: &b,
                bv,
                variant,
                x,
                poses: vec![pair],
            })
            .collect();
        points.extend(measure(&jobs, progress)?);
    }
    let comparisons = compare(&points);
    Ok(Outcome {
        name: "sliding",
        x_name: "x (offset of the small sphere)",
        x_column: "offset",
        points,
        fits: Vec::new(),
        comparisons,
        levels: Vec::new(),
    })
}

/// The circumference of the circle where the ideal spheres meet with the small one at
/// `x` (0 where they do not meet).
pub fn intersection_length(x: f64) -> f64 {
    if x <= 1.0 - SMALL || x >= 1.0 + SMALL {
        return 0.0;
    }
    // The circle's plane lies at d from the origin; its radius is sqrt(1 - d^2).
    let d = (x * x + 1.0 - SMALL * SMALL) / (2.0 * x);
    std::f64::consts::TAU * (1.0 - d * d).max(0.0).sqrt()
}

/// Contacts per unit length of the intersection curve: the least-squares factor `k` of
/// contacts = k · [`intersection_length`] over the OBB points where the spheres touch.
/// `None` without such points.
pub fn contacts_per_length(points: &[Point]) -> Option<f64> {
    let touching = of_kind(points, BvKind::Obb)
        .into_iter()
        .filter(|p| p.contacts > 0.0);
    let (cl, ll) = touching.fold((0.0, 0.0), |(cl, ll), p| {
        let l = intersection_length(p.x);
        (cl + p.contacts * l, ll + l * l)
    });
    (ll > 0.0).then(|| cl / ll)
}

fn compare(points: &[Point]) -> Vec<Comparison> {
    let obb = of_kind(points, BvKind::Obb);
    let others = [
        ("AABB", of_kind(points, BvKind::Aabb)),
        ("sphere", of_kind(points, BvKind::Sphere)),
        (
            "AABB (re-wrapped test)",
            of_variant(points, BvKind::Aabb, Variant::Rewrapped),
        ),
        (
            "sphere (minimal)",
            of_variant(points, BvKind::Sphere, Variant::MinimalSpheres),
        ),
    ];
    let touching: Vec<&Point> = obb.iter().filter(|p| p.contacts > 0.0).collect();
    let mut out = Vec::new();
    let (first, last) = (touching.first(), touching.last());
    out.push(Comparison::new(
        "contacts from / to x",
        "0.2 / 1.8",
        match (first, last) {
            (Some(f), Some(l)) => format!("{:.3} / {:.3}", f.x, l.x),
            _ => "no contacts".into(),
        },
    ));
    let most = binned_medians(&touching, |p| p.contacts)
        .into_iter()
        .max_by(|p, q| p.1.total_cmp(&q.1));
    out.push(Comparison::new(
        "most contacts (median) at x",
        "about 0.6",
        most.map_or("-".into(), |(lo, contacts)| {
            format!("{lo:.1} to {:.1} ({contacts:.0} contacts)", lo + 0.1)
        }),
    ));
    out.push(Comparison::new(
        "contacts per unit length of intersection curve",
        "about 70",
        contacts_per_length(points).map_or("-".into(), |k| format!("{k:.0}")),
    ));
    for (name, series) in &others {
        let dissertation = if name.starts_with("AABB") {
            "about 25"
        } else {
            "about 30"
        };
        let before: Vec<f64> = ratios(series, &obb, |p| {
            p.x >= 0.1 && p.x < 0.2 && p.contacts == 0.0
        });
        out.push(Comparison::new(
            &format!("{name} / OBB volume tests just before contact (0.1 <= x < 0.2)"),
            dissertation,
            range(&before, "median", "max"),
        ));
    }
    for (name, series) in &others {
        let during = ratios(series, &obb, |p| p.contacts > 0.0);
        out.push(Comparison::new(
            &format!("{name} / OBB volume tests in contact"),
            "2 to 9",
            deciles(&during),
        ));
    }
    let cheapest = binned_medians(&touching, |p| p.bv_tests() / p.contacts)
        .into_iter()
        .min_by(|p, q| p.1.total_cmp(&q.1));
    out.push(Comparison::new(
        "least OBB contact cost (median volume tests per contact) at x",
        "near 1.3 (the most transverse contact, x = 1.28)",
        cheapest.map_or("-".into(), |(lo, cost)| {
            format!("{lo:.1} to {:.1} ({cost:.1} tests per contact)", lo + 0.1)
        }),
    ));
    let per_test = |series: &[Point]| {
        median(
            series
                .iter()
                .filter(|p| p.contacts > 0.0 && p.bv_tests() > 0.0)
                .map(|p| p.seconds / p.bv_tests())
                .collect(),
        )
    };
    if let Some(o) = per_test(&obb) {
        for (name, series) in &others {
            // Table 5.2: AABB tests 1.36 to 1.38 µs, spheres 0.92 to 0.97, OBBs 5.09 to 7.44.
            let dissertation = if name.starts_with("AABB") {
                "3.7 to 5.4"
            } else {
                "5.2 to 8.1"
            };
            out.push(Comparison::new(
                &format!("time per volume test, OBB / {name} (whole queries in contact)"),
                &format!("{dissertation} (the tests alone, Table 5.2)"),
                per_test(series).map_or("-".into(), |t| format!("{:.2}", o / t)),
            ));
        }
    }
    out
}

/// The median of `value` over each tenth of x from 0.2 to 1.8 where the spheres touch
/// (bins of at least 3 points): one query per step is noisy. Each bin is named by its
/// lower end.
fn binned_medians(touching: &[&Point], value: impl Fn(&Point) -> f64) -> Vec<(f64, f64)> {
    (2..18)
        .filter_map(|b| {
            let lo = f64::from(b) / 10.0;
            let values: Vec<f64> = touching
                .iter()
                .filter(|p| p.x >= lo && p.x < lo + 0.1)
                .map(|p| value(p))
                .collect();
            if values.len() < 3 {
                return None;
            }
            Some((lo, median(values)?))
        })
        .collect()
}

/// `series` / `obb` volume tests at the points `keep` accepts (of the OBB series).
fn ratios(series: &[Point], obb: &[Point], keep: impl Fn(&Point) -> bool) -> Vec<f64> {
    series
        .iter()
        .zip(obb)
        .filter(|(_, o)| keep(o) && o.bv_tests() > 0.0)
        .map(|(s, o)| s.bv_tests() / o.bv_tests())
        .collect()
}

fn range(values: &[f64], middle: &str, top: &str) -> String {
    let max = values.iter().copied().fold(f64::NAN, f64::max);
    match median(values.to_vec()) {
        Some(m) => format!("{m:.1} {middle}, {max:.1} {top}"),
        None => "-".into(),
    }
}

/// The 10th and 90th percentiles.
fn deciles(values: &[f64]) -> String {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v.get(((v.len().saturating_sub(1)) as f64 * q).round() as usize);
    match (at(0.1), at(0.9)) {
        (Some(lo), Some(hi)) => format!("{lo:.1} to {hi:.1} (10th to 90th percentile)"),
        _ => "-".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_intersection_circle_is_largest_where_the_small_sphere_sits_on_the_big_ones_rim() {
        assert_eq!(intersection_length(0.1), 0.0);
        assert_eq!(intersection_length(1.9), 0.0);
        // At x = 0.6 the circle passes through both spheres' equators' plane x = 0.6:
        // d = (0.36 + 0.36) / 1.2 = 0.6, radius 0.8.
        assert!((intersection_length(0.6) - std::f64::consts::TAU * 0.8).abs() < 1e-12);
    }
}
