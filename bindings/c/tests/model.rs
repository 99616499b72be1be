//! The one-model entry points (rays, closest points, winding numbers, signed distances),
//! the Hausdorff distance and contact geometry, called as C would call them, each answer checked against the Rust API's on the cow,
//! and each refusal with its code and message.

mod common;

use obbtree::build::BuildOptions;
use obbtree::format::ObbtFile;
use obbtree::query::{
    all_ray_hits, cast_rays, closest_points, signed_distances, winding_numbers, ClosestOptions,
    Pose, Ray, RayMode, RayOptions, WindingAccuracy, WindingOptions,
};
use obbtree_c::*;
use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated, valid until the next call on this thread.
    unsafe { CStr::from_ptr(obbtree_last_error()) }
        .to_string_lossy()
        .into_owned()
}

#[track_caller]
fn ok(status: ObbtreeStatus) {
    assert_eq!(status, ObbtreeStatus::Ok, "{}", last_error());
}

#[track_caller]
fn fails(status: ObbtreeStatus, expected: ObbtreeStatus, needle: &str) {
    let message = last_error();
    assert_eq!(status, expected, "message: {message}");
    assert!(message.contains(needle), "{needle:?} not in {message:?}");
}

/// A turn about z by 0.5 rad and a shift: the model's pose in every query.
const POSE: [f64; 12] = {
    // cos 0.5, sin 0.5 to f64 precision.
    let (c, s) = (0.877_582_561_890_372_8, 0.479_425_538_604_203);
    [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0, 0.3, -0.2, 0.1]
};

/// The cow's tree opened through C and through Rust, and query points around it.
struct Cow {
    tree: *mut ObbtreeTree,
    file: ObbtFile,
    pose: Pose,
    points: Vec<[f64; 3]>,
    rays: Vec<Ray>,
    dir: std::path::PathBuf,
}

impl Cow {
    fn new(name: &str) -> Cow {
        let dir = common::scratch(name);
        let path = common::build_cow(&dir, "cow.obbt", &BuildOptions::default());
        let c_path = CString::new(path.to_str().expect("UTF-8 path")).expect("no NUL");
        let mut tree = null_mut();
        // SAFETY: a C string and a writable pointer.
        ok(unsafe { obbtree_open(c_path.as_ptr(), &mut tree) });
        let file = ObbtFile::open(&path).expect("the tree opens");
        let pose = Pose::from_row_major(&POSE).expect("a rigid pose");
        // A grid through and around the model (its bounds are about ±1 on each axis), and
        // rays from a ring of points towards the middle, some missing it.
        let mut points = Vec::new();
        for i in 0..7 {
            for j in 0..7 {
                for k in 0..5 {
                    let at = |n: i32, steps: i32| -1.2 + 2.4 * f64::from(n) / f64::from(steps);
                    points.push([at(i, 6), at(j, 6), at(k, 4)]);
                }
            }
        }
        let rays = (0..200)
            .map(|i| {
                let a = f64::from(i) * 0.173;
                let origin = [3.0 * a.cos(), 3.0 * a.sin(), 0.4 * (a * 3.1).sin()];
                let aim = [0.2 * (a * 1.7).cos(), 0.3 * (a * 2.3).sin(), 0.05];
                let direction = [aim[0] - origin[0], aim[1] - origin[1], aim[2] - origin[2]];
                Ray { origin, direction }
            })
            .collect();
        Cow {
            tree,
            file,
            pose,
            points,
            rays,
            dir,
        }
    }

    fn flat_points(&self) -> Vec<f64> {
        self.points.iter().flatten().copied().collect()
    }

    fn origins_and_directions(&self) -> (Vec<f64>, Vec<f64>) {
        (
            self.rays.iter().flat_map(|r| r.origin).collect(),
            self.rays.iter().flat_map(|r| r.direction).collect(),
        )
    }
}

impl Drop for Cow {
    fn drop(&mut self) {
        // SAFETY: opened by Cow::new, closed once.
        unsafe { obbtree_close(self.tree) };
        std::fs::remove_dir_all(&self.dir).ok();
    }
}

#[test]
fn rays_equal_the_rust_answers() {
    let cow = Cow::new("model-rays");
    let (origins, directions) = cow.origins_and_directions();
    let n = cow.rays.len();
    for (mode, c_mode) in [
        (RayMode::Closest, OBBTREE_RAY_CLOSEST),
        (RayMode::Any, OBBTREE_RAY_ANY),
    ] {
        let options = RayOptions { mode, t_max: 10.0 };
        let expected = cast_rays(&cow.file, &cow.pose, &cow.rays, &options).expect("rays");
        for threads in [0, 1] {
            let mut results = vec![std::mem::MaybeUninit::<ObbtreeRayResult>::uninit(); n];
            // SAFETY: an open tree, 12 doubles, 3n doubles each, n writable results.
            ok(unsafe {
                obbtree_rays(
                    cow.tree,
                    POSE.as_ptr(),
                    origins.as_ptr(),
                    directions.as_ptr(),
                    n,
                    10.0,
                    c_mode,
                    threads,
                    results.as_mut_ptr().cast(),
                    n,
                )
            });
            let mut hits = 0;
            for ((got, want), ray) in results.iter().zip(&expected).zip(&cow.rays) {
                // SAFETY: the call wrote every result.
                let got = unsafe { got.assume_init() };
                assert_eq!(got.hit, want.hit.is_some());
                match &want.hit {
                    Some(h) => {
                        hits += 1;
                        assert_eq!(got.closest.t, h.t);
                        assert_eq!(got.closest.triangle, h.triangle);
                        assert_eq!(got.closest.barycentric, h.barycentric);
                        assert_eq!(got.closest.normal, h.normal);
                        assert_eq!(got.closest.point, ray.at(h.t));
                    }
                    None => {
                        assert_eq!(got.closest.t, f64::INFINITY);
                        assert_eq!(got.closest.triangle, OBBTREE_NO_TRIANGLE);
                    }
                }
                assert_eq!(got.work.bv_overlap, want.work.bv_overlap);
            }
            assert!(hits > 20 && hits < n, "{hits} of {n} rays hit");
        }
    }
}

#[test]
fn all_hits_fill_the_buffer_ray_by_ray_and_report_short_ones() {
    let cow = Cow::new("model-all-hits");
    let (origins, directions) = cow.origins_and_directions();
    let n = cow.rays.len();
    let expected = all_ray_hits(&cow.file, &cow.pose, &cow.rays, f64::INFINITY).expect("rays");
    let total: usize = expected.iter().map(|r| r.hits.len()).sum();
    assert!(total > 40, "{total} hits");
    let call = |hits: &mut [ObbtreeRayHit], results: &mut [ObbtreeRayHits], total: &mut usize| {
        // SAFETY: as in `rays_equal_the_rust_answers`, `hits.len()` writable hits (NULL for
        // none) and a writable total.
        unsafe {
            obbtree_ray_all_hits(
                cow.tree,
                POSE.as_ptr(),
                origins.as_ptr(),
                directions.as_ptr(),
                n,
                f64::INFINITY,
                0,
                results.as_mut_ptr(),
                results.len(),
                if hits.is_empty() {
                    null_mut()
                } else {
                    hits.as_mut_ptr()
                },
                hits.len(),
                total,
            )
        }
    };
    let mut results = vec![ObbtreeRayHits::default(); n];
    let mut reported = 0;
    // Counts only.
    ok(call(&mut [], &mut results, &mut reported));
    assert_eq!(reported, total);
    let blank = ObbtreeRayHit {
        t: 0.0,
        point: [0.0; 3],
        barycentric: [0.0; 3],
        normal: [0.0; 3],
        triangle: 0,
    };
    let mut hits = vec![blank; total];
    ok(call(&mut hits, &mut results, &mut reported));
    for ((result, want), ray) in results.iter().zip(&expected).zip(&cow.rays) {
        assert_eq!(result.hit_count, want.hits.len());
        let got = &hits[result.hit_offset..result.hit_offset + result.hit_count];
        for (g, w) in got.iter().zip(&want.hits) {
            assert_eq!((g.t, g.triangle, g.normal), (w.t, w.triangle, w.normal));
            assert_eq!(g.point, ray.at(w.t));
        }
    }
    // A short buffer: everything counted, the first hits written.
    let mut short = vec![blank; total / 2];
    fails(
        call(&mut short, &mut results, &mut reported),
        ObbtreeStatus::BufferTooSmall,
        &format!("holds {} hits but {total} are needed", total / 2),
    );
    assert_eq!(reported, total);
    assert_eq!(short[..], hits[..total / 2]);
}

#[test]
fn closest_points_equal_the_rust_answers() {
    let cow = Cow::new("model-closest");
    let flat = cow.flat_points();
    let n = cow.points.len();
    for max_distance in [f64::INFINITY, 0.2] {
        let options = ClosestOptions { max_distance };
        let expected = closest_points(&cow.file, &cow.pose, &cow.points, &options).expect("ok");
        let mut results = vec![std::mem::MaybeUninit::<ObbtreeClosestResult>::uninit(); n];
        // SAFETY: an open tree, 12 doubles, 3n doubles, n writable results.
        ok(unsafe {
            obbtree_closest_points(
                cow.tree,
                POSE.as_ptr(),
                flat.as_ptr(),
                n,
                max_distance,
                2,
                results.as_mut_ptr().cast(),
                n,
            )
        });
        let mut found = 0;
        for (got, want) in results.iter().zip(&expected) {
            // SAFETY: the call wrote every result.
            let got = unsafe { got.assume_init() };
            assert_eq!(got.found, want.closest.is_some());
            assert_eq!(got.distance, want.distance());
            if let Some(c) = want.closest {
                found += 1;
                assert_eq!((got.point, got.triangle), (c.point, c.triangle));
                assert_eq!(got.feature_index, u32::from(c.feature.index()));
                let kind = match got.feature {
                    ObbtreeFeature::Face => "face",
                    ObbtreeFeature::Edge => "edge",
                    ObbtreeFeature::Vertex => "vertex",
                };
                assert_eq!(kind, c.feature.name());
            }
        }
        if max_distance.is_finite() {
            assert!(
                found > 0 && found < n,
                "{found} of {n} within {max_distance}"
            );
        } else {
            assert_eq!(found, n);
        }
    }
}

#[test]
fn winding_numbers_and_signed_distances_equal_the_rust_answers() {
    let cow = Cow::new("model-winding");
    let flat = cow.flat_points();
    let n = cow.points.len();
    for (rule, parameter, accuracy) in [
        (
            OBBTREE_WINDING_BETA,
            2.0,
            WindingAccuracy::Beta { beta: 2.0 },
        ),
        (
            OBBTREE_WINDING_BOUNDED,
            1e-3,
            WindingAccuracy::Bounded { tolerance: 1e-3 },
        ),
        (OBBTREE_WINDING_EXACT, 0.0, WindingAccuracy::Exact),
    ] {
        let options = WindingOptions { accuracy };
        let expected = winding_numbers(&cow.file, &cow.pose, &cow.points, &options).expect("ok");
        let (mut values, mut bounds) = (vec![0.0; n], vec![0.0; n]);
        // SAFETY: an open tree, 12 doubles, 3n doubles, n writable doubles twice.
        ok(unsafe {
            obbtree_winding_numbers(
                cow.tree,
                POSE.as_ptr(),
                flat.as_ptr(),
                n,
                rule,
                parameter,
                0,
                values.as_mut_ptr(),
                bounds.as_mut_ptr(),
                n,
            )
        });
        let want: Vec<f64> = expected.iter().map(|w| w.value).collect();
        let want_bounds: Vec<f64> = expected.iter().map(|w| w.error_bound).collect();
        assert_eq!((&values, &bounds), (&want, &want_bounds));
        let inside = values.iter().filter(|&&w| w > 0.5).count();
        assert!(inside > 0 && inside < n, "{inside} of {n} inside");
        // Without the bounds.
        // SAFETY: as above, no bounds buffer.
        ok(unsafe {
            obbtree_winding_numbers(
                cow.tree,
                POSE.as_ptr(),
                flat.as_ptr(),
                n,
                rule,
                parameter,
                1,
                values.as_mut_ptr(),
                null_mut(),
                n,
            )
        });
        assert_eq!(values, want);
        let signed = signed_distances(&cow.file, &cow.pose, &cow.points, &options).expect("ok");
        // SAFETY: as above.
        ok(unsafe {
            obbtree_signed_distances(
                cow.tree,
                POSE.as_ptr(),
                flat.as_ptr(),
                n,
                rule,
                parameter,
                0,
                values.as_mut_ptr(),
                n,
            )
        });
        assert_eq!(values, signed);
    }
}

#[test]
fn bad_arguments_are_refused_with_their_code_and_message() {
    let cow = Cow::new("model-errors");
    let mut flat = cow.flat_points();
    let (origins, mut directions) = cow.origins_and_directions();
    let n = cow.points.len();
    let mut values = vec![0.0; n];
    let winding = |tree: *const ObbtreeTree,
                   pose: &[f64; 12],
                   points: &[f64],
                   rule: i32,
                   parameter: f64,
                   threads: usize,
                   values: &mut [f64]| {
        // SAFETY: `points.len() / 3` points, `values.len()` writable doubles.
        unsafe {
            obbtree_winding_numbers(
                tree,
                pose.as_ptr(),
                points.as_ptr(),
                points.len() / 3,
                rule,
                parameter,
                threads,
                values.as_mut_ptr(),
                null_mut(),
                values.len(),
            )
        }
    };
    let beta = OBBTREE_WINDING_BETA;
    fails(
        winding(null(), &POSE, &flat, beta, 2.0, 0, &mut values),
        ObbtreeStatus::NullPointer,
        "tree is NULL",
    );
    fails(
        winding(cow.tree, &POSE, &flat, 7, 2.0, 0, &mut values),
        ObbtreeStatus::BadArgument,
        "rule is 7",
    );
    fails(
        winding(cow.tree, &POSE, &flat, beta, 1.0, 0, &mut values),
        ObbtreeStatus::BadArgument,
        "beta",
    );
    fails(
        winding(cow.tree, &POSE, &flat, beta, 2.0, 5000, &mut values),
        ObbtreeStatus::BadArgument,
        "threads is 5000",
    );
    fails(
        winding(cow.tree, &POSE, &flat, beta, 2.0, 0, &mut values[1..]),
        ObbtreeStatus::BadArgument,
        &format!("values holds {} values but there are {n} queries", n - 1),
    );
    let mut stretched = POSE;
    stretched[0] *= 2.0;
    fails(
        winding(cow.tree, &stretched, &flat, beta, 2.0, 0, &mut values),
        ObbtreeStatus::Pose,
        "pose",
    );
    flat[3 * 5 + 1] = f64::NAN;
    fails(
        winding(cow.tree, &POSE, &flat, beta, 2.0, 0, &mut values),
        ObbtreeStatus::BadArgument,
        "query point 5",
    );
    let mut closest = vec![std::mem::MaybeUninit::<ObbtreeClosestResult>::uninit(); n];
    // SAFETY: 3n doubles, n writable results.
    let status = unsafe {
        obbtree_closest_points(
            cow.tree,
            POSE.as_ptr(),
            flat.as_ptr(),
            n,
            -1.0,
            0,
            closest.as_mut_ptr().cast(),
            n,
        )
    };
    fails(status, ObbtreeStatus::BadArgument, "max_distance");

    let m = cow.rays.len();
    let mut rays = vec![std::mem::MaybeUninit::<ObbtreeRayResult>::uninit(); m];
    let mut cast = |directions: &[f64], t_max: f64, mode: i32| {
        // SAFETY: 3m doubles each, m writable results.
        unsafe {
            obbtree_rays(
                cow.tree,
                POSE.as_ptr(),
                origins.as_ptr(),
                directions.as_ptr(),
                m,
                t_max,
                mode,
                0,
                rays.as_mut_ptr().cast(),
                m,
            )
        }
    };
    fails(
        cast(&directions, 1.0, 9),
        ObbtreeStatus::BadArgument,
        "mode is 9",
    );
    fails(
        cast(&directions, 0.0, OBBTREE_RAY_ANY),
        ObbtreeStatus::BadArgument,
        "t_max",
    );
    directions[3 * 4..3 * 5].copy_from_slice(&[0.0; 3]);
    fails(
        cast(&directions, 1.0, OBBTREE_RAY_CLOSEST),
        ObbtreeStatus::BadArgument,
        "ray 4: direction must not be zero",
    );
    // SAFETY: a NULL origins pointer with a nonzero count is refused before reading.
    let status = unsafe {
        obbtree_rays(
            cow.tree,
            POSE.as_ptr(),
            null(),
            directions.as_ptr(),
            m,
            1.0,
            OBBTREE_RAY_CLOSEST,
            0,
            rays.as_mut_ptr().cast(),
            m,
        )
    };
    fails(status, ObbtreeStatus::NullPointer, "origins is NULL");
}

#[test]
fn hausdorff_equals_the_rust_answer() {
    let cow = Cow::new("model-hausdorff");
    let options = obbtree::query::HausdorffOptions {
        symmetric: true,
        ..Default::default()
    };
    let want =
        obbtree::query::hausdorff(&cow.file, &Pose::identity(), &cow.file, &cow.pose, &options)
            .expect("answers");
    let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let mut out = std::mem::MaybeUninit::<ObbtreeHausdorffResult>::uninit();
    // SAFETY: open trees, 12 doubles each, a writable result.
    ok(unsafe {
        obbtree_hausdorff(
            cow.tree,
            identity.as_ptr(),
            cow.tree,
            POSE.as_ptr(),
            0.0,
            0.0,
            true,
            out.as_mut_ptr(),
        )
    });
    // SAFETY: written by the successful call.
    let got = unsafe { out.assume_init() };
    assert_eq!(
        (got.distance, got.upper_bound),
        (want.distance, want.upper_bound)
    );
    assert_eq!((got.point_a, got.point_b), (want.point_a, want.point_b));
    assert_eq!((got.tri_a, got.tri_b), (want.tri_a, want.tri_b));
    assert!(got.distance > 0.1, "{}", got.distance);
    // SAFETY: as above.
    let status = unsafe {
        obbtree_hausdorff(
            cow.tree,
            identity.as_ptr(),
            cow.tree,
            POSE.as_ptr(),
            -1.0,
            0.0,
            false,
            out.as_mut_ptr(),
        )
    };
    fails(
        status,
        ObbtreeStatus::BadArgument,
        "rel_err must be finite and at least 0",
    );
    // SAFETY: a NULL second tree is refused before anything is read.
    let status = unsafe {
        obbtree_hausdorff(
            cow.tree,
            identity.as_ptr(),
            null(),
            POSE.as_ptr(),
            0.0,
            0.0,
            false,
            out.as_mut_ptr(),
        )
    };
    fails(status, ObbtreeStatus::NullPointer, "b is NULL");
}

#[test]
fn contact_geometry_equals_the_rust_answer_and_reports_short_buffers() {
    let cow = Cow::new("model-contacts");
    let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let options = obbtree::query::CollideOptions {
        geometry: true,
        ..Default::default()
    };
    let want = obbtree::query::PairQuery::new(&cow.file, &cow.file)
        .expect("a pair")
        .collide(&Pose::identity(), &cow.pose, &options)
        .expect("answers");
    assert!(want.contacts.len() > 10, "{} contacts", want.contacts.len());
    let mut pair = null_mut();
    // SAFETY: open trees and a writable pointer.
    ok(unsafe { obbtree_pair_new(cow.tree, cow.tree, &mut pair) });
    let blank = ObbtreeContact {
        tri_a: 0,
        tri_b: 0,
        coplanar: false,
        point_count: 0,
        points: [[0.0; 3]; 6],
        residual: 0.0,
    };
    let call = |buffer: &mut [ObbtreeContact]| {
        let (mut count, mut length, mut area) = (0usize, 0.0, 0.0);
        // SAFETY: a live handle, 12 doubles each, `buffer.len()` writable contacts (NULL
        // for none) and three writable totals.
        let status = unsafe {
            obbtree_pair_contact_geometry(
                pair,
                identity.as_ptr(),
                POSE.as_ptr(),
                if buffer.is_empty() {
                    null_mut()
                } else {
                    buffer.as_mut_ptr()
                },
                buffer.len(),
                &mut count,
                &mut length,
                &mut area,
            )
        };
        (status, count, length, area)
    };
    let mut all = vec![blank; want.contacts.len()];
    let (status, count, length, area) = call(&mut all);
    ok(status);
    assert_eq!(count, want.contacts.len());
    assert_eq!((length, area), (want.curve_length(), want.overlap_area()));
    for (got, c) in all.iter().zip(&want.contacts) {
        assert_eq!((got.tri_a, got.tri_b), (c.tri_a, c.tri_b));
        let points: Vec<[f64; 3]> = c.intersection.points().iter().map(|&p| p.into()).collect();
        assert_eq!(&got.points[..got.point_count as usize], points.as_slice());
    }
    let mut short = vec![blank; 3];
    fails(
        call(&mut short).0,
        ObbtreeStatus::BufferTooSmall,
        &format!("holds 3 contacts but {} are needed", want.contacts.len()),
    );
    // (Unused points are NaN: compare what is used.)
    let used = |c: &ObbtreeContact| {
        (
            c.tri_a,
            c.tri_b,
            c.points[..c.point_count as usize].to_vec(),
        )
    };
    assert_eq!(
        short.iter().map(used).collect::<Vec<_>>(),
        all[..3].iter().map(used).collect::<Vec<_>>()
    );
    // SAFETY: made above, freed once.
    unsafe { obbtree_pair_free(pair) };
}
