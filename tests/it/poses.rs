//! Poses as people have them: four layouts, nalgebra types, and rotations printed with few
//! decimals repaired to the nearest rotation (or refused, without the repair).
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::indexing_slicing)]

use obbtree::nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use obbtree::query::{Pose, PoseError, PoseFormat, MAX_REPAIR};

fn rotation() -> Rotation3<f64> {
    Rotation3::from_euler_angles(0.3, -1.1, 2.0)
}

const T: [f64; 3] = [1.5, -2.0, 0.25];

/// The same pose written in each format.
fn written(format: PoseFormat) -> Vec<f64> {
    let r = rotation();
    let m = r.matrix();
    let q = UnitQuaternion::from_rotation_matrix(&r);
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    match format {
        PoseFormat::RotationTranslation => {
            let mut v: Vec<f64> = (0..9).map(|k| m[(k / 3, k % 3)]).collect();
            v.extend(T);
            v
        }
        PoseFormat::TranslationQuaternionWxyz => [T[0], T[1], T[2], w, x, y, z].to_vec(),
        PoseFormat::TranslationQuaternionXyzw => [T[0], T[1], T[2], x, y, z, w].to_vec(),
        PoseFormat::Matrix4 => {
            let mut v = Vec::new();
            for i in 0..3 {
                v.extend([m[(i, 0)], m[(i, 1)], m[(i, 2)], T[i]]);
            }
            v.extend([0.0, 0.0, 0.0, 1.0]);
            v
        }
    }
}

fn close(a: &Pose, b: &Pose) -> bool {
    (a.rotation() - b.rotation()).abs().max() < 1e-12
        && (a.translation_vector() - b.translation_vector())
            .abs()
            .max()
            < 1e-12
}

#[test]
fn every_format_reads_the_same_pose() {
    let reference = Pose::new(*rotation().matrix(), Vector3::from(T)).unwrap();
    for format in PoseFormat::ALL {
        let values = written(format);
        assert_eq!(values.len(), format.numbers());
        for repair in [false, true] {
            let parsed = format.parse(&values, repair).unwrap();
            assert!(close(&parsed.pose, &reference), "{format:?}");
            assert!(
                parsed.correction < 1e-12,
                "{format:?}: {}",
                parsed.correction
            );
        }
        assert_eq!(PoseFormat::from_name(format.name()), Some(format));
        // One number short or over is refused, never guessed.
        for n in [values.len() - 1, values.len() + 1] {
            let mut v = values.clone();
            v.resize(n, 0.0);
            assert!(matches!(
                format.parse(&v, true),
                Err(PoseError::WrongCount { got, .. }) if got == n
            ));
        }
    }
}

#[test]
fn nalgebra_types_convert_both_ways() {
    let iso = Isometry3::from_parts(
        Translation3::new(T[0], T[1], T[2]),
        UnitQuaternion::from_rotation_matrix(&rotation()),
    );
    let pose = Pose::from_isometry(&iso).unwrap();
    let reference = Pose::new(*rotation().matrix(), Vector3::from(T)).unwrap();
    assert!(close(&pose, &reference));
    let back = pose.to_isometry();
    assert!((back.to_homogeneous() - iso.to_homogeneous()).abs().max() < 1e-12);
    let q = Pose::from_quaternion(&iso.rotation, &Vector3::from(T)).unwrap();
    assert!(close(&q, &reference));
    let p = Vector3::new(0.1, 0.2, 0.3);
    assert!((pose.apply(&p) - iso.transform_point(&p.into()).coords).norm() < 1e-12);
}

/// A rotation printed with 4 decimals is off orthonormal by about 1e-4: refused as it is,
/// read as the nearest rotation with the repair, which reports its size.
#[test]
fn rotations_with_four_decimals_need_the_repair() {
    let rounded: Vec<f64> = written(PoseFormat::RotationTranslation)
        .iter()
        .map(|v| (v * 1e4).round() / 1e4)
        .collect();
    assert!(matches!(
        PoseFormat::RotationTranslation.parse(&rounded, false),
        Err(PoseError::NotOrthonormal { .. })
    ));
    let repaired = PoseFormat::RotationTranslation
        .parse(&rounded, true)
        .unwrap();
    assert!(repaired.correction > 1e-6 && repaired.correction < 1e-4);
    let r = repaired.pose.rotation();
    assert!((r.transpose() * r - Matrix3::identity()).abs().max() < 1e-14);
    assert!((r - rotation().matrix()).abs().max() < 1e-4);
    // The same for a quaternion: normalised, and the norm's error is the correction.
    let mut q = written(PoseFormat::TranslationQuaternionWxyz);
    for v in &mut q[3..] {
        *v = (*v * 1e4).round() / 1e4;
    }
    let format = PoseFormat::TranslationQuaternionWxyz;
    assert!(matches!(
        format.parse(&q, false),
        Err(PoseError::NotUnitQuaternion { .. })
    ));
    let repaired = format.parse(&q, true).unwrap();
    assert!(repaired.correction > 1e-6 && repaired.correction < 2e-4);
}

#[test]
fn what_no_repair_can_fix_is_refused() {
    let format = PoseFormat::RotationTranslation;
    let scaled = [2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0];
    assert!(matches!(
        format.parse(&scaled, true),
        Err(PoseError::BeyondRepair { correction }) if correction > MAX_REPAIR
    ));
    let mirror = [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    for repair in [false, true] {
        assert!(matches!(
            format.parse(&mirror, repair),
            Err(PoseError::Reflection { .. })
        ));
    }
    let mut not_finite = written(format);
    not_finite[10] = f64::NAN;
    assert!(matches!(
        format.parse(&not_finite, true),
        Err(PoseError::NotFinite { index: 10, .. })
    ));
    let mut projective = written(PoseFormat::Matrix4);
    projective[14] = 0.5;
    assert!(matches!(
        PoseFormat::Matrix4.parse(&projective, true),
        Err(PoseError::NotRigid { .. })
    ));
    let zero = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    assert!(PoseFormat::TranslationQuaternionXyzw
        .parse(&zero, true)
        .is_err());
}

/// The largest entry of `|RᵀR − I|`.
fn deviation(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).abs().max()
}

/// A rotation within the tolerance of orthonormal but beyond rounding (scaled, stretched
/// along a direction, sheared, or disturbed at random by up to 1e-6) becomes the nearest
/// rotation, the same as the SVD's polar factor, rigid to rounding; a rotation computed in
/// f64 (here from a quaternion) is kept bit for bit.
#[test]
fn rotations_within_the_tolerance_are_made_rigid() {
    let mut rng = obbtree::generate::Rng::new(5);
    for k in 0..4000 {
        let q = rng.uniform_rotation();
        let kept = Pose::new(q, Vector3::zeros()).unwrap();
        assert_eq!(*kept.rotation(), q, "case {k}: a computed rotation changed");
        let e = match k % 4 {
            0 => Matrix3::identity() * rng.signed(),
            1 => {
                let u = Vector3::new(rng.signed(), rng.signed(), rng.signed()).normalize();
                u * u.transpose()
            }
            2 => {
                let mut e = Matrix3::zeros();
                e[(k / 4 % 3, (k / 12 + 1) % 3)] = rng.signed();
                e
            }
            _ => Matrix3::from_fn(|_, _| rng.signed()),
        };
        let given = q * (Matrix3::identity() + e * (4.9e-7 * rng.unit()));
        let Ok(pose) = Pose::new(given, Vector3::zeros()) else {
            continue;
        };
        let r = pose.rotation();
        assert!(
            deviation(r) <= 8.0 * f64::EPSILON,
            "case {k}: deviation {:e} from {:e}",
            deviation(r),
            deviation(&given)
        );
        let svd = given.svd(true, true);
        let polar = svd.u.unwrap() * svd.v_t.unwrap();
        assert!(
            (r - polar).abs().max() < 1e-14,
            "case {k}: {r} against the polar factor {polar}"
        );
    }
}
