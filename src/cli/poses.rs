//! Poses from the command line and from pose files, in any [`PoseFormat`], optionally
//! repaired to the nearest rotation.

use super::input::{input_lines, parse_numbers, read_input};
use super::{Failure, WithContext};
use clap::{Args, ValueEnum};
use obbtree::query::{ParsedPose, Pose, PoseFormat, Repairs, ORTHONORMAL_TOLERANCE};
use std::path::PathBuf;

/// Where the two models are: one pose pair from flags, or a batch file.
#[derive(Args, Debug, Clone)]
pub struct PoseArgs {
    /// Pose of A (default: identity): numbers in the --pose-format, separated by commas or
    /// spaces. World point = R p + T.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pose_a: Option<String>,
    /// Pose of B, as --pose-a.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pose_b: Option<String>,
    /// A batch of poses, a file (`-` for stdin): each line holds pose A then pose B (24
    /// numbers in the default format) separated by spaces or commas; blank lines and lines
    /// starting with `#` are skipped. Prints one JSON object per pose, in input order, each
    /// with "pose": its index from 0 (skipped lines do not count); queries run in parallel.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["pose_a", "pose_b"])]
    pub poses: Option<PathBuf>,
    /// How the numbers of a pose are laid out: rt = rotation row-major then translation
    /// (12); tq-wxyz = translation then unit quaternion w x y z (7); tq-xyzw = translation
    /// then quaternion x y z w, as in ROS (7); matrix4 = 4x4 row-major matrix with last row
    /// 0 0 0 1 (16).
    #[arg(long, value_enum, default_value_t = PoseFormatArg::Rt, value_name = "FORMAT")]
    pub pose_format: PoseFormatArg,
    /// Replace each rotation by the nearest rotation (a quaternion by its normalisation),
    /// for poses printed with few decimals; corrections above 1e-6 are reported on stderr,
    /// above 1e-2 refused. Without it a rotation must be orthonormal within 1e-6.
    #[arg(long)]
    pub orthonormalize: bool,
}

/// Where one model is (the one-model queries): a pose from a flag.
#[derive(Args, Debug, Clone)]
pub struct ModelPoseArgs {
    /// Pose of the model (default: identity): numbers in the --pose-format, separated by
    /// commas or spaces. World point = R p + T.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pose: Option<String>,
    /// How the numbers of the pose are laid out, as for the pair queries: rt (12), tq-wxyz
    /// (7), tq-xyzw (7, ROS order), matrix4 (16).
    #[arg(long, value_enum, default_value_t = PoseFormatArg::Rt, value_name = "FORMAT")]
    pub pose_format: PoseFormatArg,
    /// Replace the rotation by the nearest rotation (corrections above 1e-6 reported, above
    /// 1e-2 refused).
    #[arg(long)]
    pub orthonormalize: bool,
}

impl ModelPoseArgs {
    /// The pose of --pose (identity without it).
    pub fn pose(&self) -> Result<Pose, Failure> {
        let mut repairs = Repairs::default();
        let format = self.pose_format.format();
        let pose = flag_pose(
            self.pose.as_deref(),
            "--pose",
            format,
            self.orthonormalize,
            &mut repairs,
        )?;
        report(&repairs, "--pose");
        Ok(pose)
    }
}

/// `--pose-format` values, named as [`PoseFormat::name`].
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum PoseFormatArg {
    /// Rotation row-major, then translation: 12 numbers.
    Rt,
    /// Translation, then unit quaternion w x y z: 7 numbers.
    #[value(name = "tq-wxyz")]
    TqWxyz,
    /// Translation, then unit quaternion x y z w (ROS order): 7 numbers.
    #[value(name = "tq-xyzw")]
    TqXyzw,
    /// 4x4 homogeneous matrix, row-major: 16 numbers.
    Matrix4,
}

impl PoseFormatArg {
    /// The library format.
    pub fn format(self) -> PoseFormat {
        match self {
            PoseFormatArg::Rt => PoseFormat::RotationTranslation,
            PoseFormatArg::TqWxyz => PoseFormat::TranslationQuaternionWxyz,
            PoseFormatArg::TqXyzw => PoseFormat::TranslationQuaternionXyzw,
            PoseFormatArg::Matrix4 => PoseFormat::Matrix4,
        }
    }
}

/// The pose given by `flag` (`text`, in `format`; the identity without it), its repair
/// noted in `repairs`.
fn flag_pose(
    text: Option<&str>,
    flag: &str,
    format: PoseFormat,
    repair: bool,
    repairs: &mut Repairs,
) -> Result<Pose, Failure> {
    let Some(text) = text else {
        return Ok(Pose::identity());
    };
    let parsed = format
        .parse(&parse_numbers(text, flag)?, repair)
        .with_context(|| flag)?;
    Ok(repairs.note(&parsed, || flag.to_string()))
}

/// Reports the repairs made while reading poses from `source`, once, on stderr.
pub fn report(repairs: &Repairs, source: &str) {
    match repairs.count {
        0 => {}
        1 => eprintln!(
            "obbtree: note: {}: rotation corrected by {:.3e} to the nearest rotation",
            repairs.at, repairs.largest
        ),
        n => eprintln!(
            "obbtree: note: {source}: {n} rotations corrected by more than {ORTHONORMAL_TOLERANCE:e}, the most by {:.3e} ({})",
            repairs.largest, repairs.at
        ),
    }
}

impl PoseArgs {
    fn parse(&self, values: &[f64]) -> Result<ParsedPose, obbtree::query::PoseError> {
        self.pose_format.format().parse(values, self.orthonormalize)
    }

    /// The pose pair of --pose-a / --pose-b (identity where absent).
    pub fn single(&self) -> Result<(Pose, Pose), Failure> {
        let mut repairs = Repairs::default();
        let (format, repair) = (self.pose_format.format(), self.orthonormalize);
        let a = flag_pose(
            self.pose_a.as_deref(),
            "--pose-a",
            format,
            repair,
            &mut repairs,
        )?;
        let b = flag_pose(
            self.pose_b.as_deref(),
            "--pose-b",
            format,
            repair,
            &mut repairs,
        )?;
        report(&repairs, "--pose-a/--pose-b");
        Ok((a, b))
    }

    /// The pose pairs of the --poses file, or `None` without one. Errors name the file,
    /// the line (from 1) and the pose (from 0, as the output's "pose" field).
    pub fn batch(&self) -> Result<Option<Vec<(Pose, Pose)>>, Failure> {
        let Some(path) = &self.poses else {
            return Ok(None);
        };
        let (shown, text) = read_input(path)?;
        let per_pose = self.pose_format.format().numbers();
        let mut repairs = Repairs::default();
        let mut out = Vec::new();
        for (line_no, line) in input_lines(&text) {
            let what = format!("{shown}: line {line_no} (pose {})", out.len());
            let values = parse_numbers(line, &what)?;
            let Some((a, b)) = values
                .split_at_checked(per_pose)
                .filter(|_| values.len() == 2 * per_pose)
            else {
                return Err(Failure::msg(format!(
                    "{what}: expected {} numbers (pose A then pose B, {} each in format {}), got {}",
                    2 * per_pose,
                    per_pose,
                    self.pose_format.format().name(),
                    values.len()
                )));
            };
            let mut pose = |values: &[f64], which: &str| -> Result<Pose, Failure> {
                let parsed = self
                    .parse(values)
                    .with_context(|| format!("{what}: pose {which}"))?;
                Ok(repairs.note(&parsed, || format!("{what}, pose {which}")))
            };
            let a = pose(a, "A")?;
            let b = pose(b, "B")?;
            out.push((a, b));
        }
        if out.is_empty() {
            return Err(Failure::msg(format!(
                "{shown}: no poses (lines of pose A then pose B)"
            )));
        }
        report(&repairs, &shown);
        Ok(Some(out))
    }
}
