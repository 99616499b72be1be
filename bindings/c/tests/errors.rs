//! The C entry points called as C would call them (through the rlib): every error path
//! gives its code and a message, short buffers report the size needed, batches equal
//! one-at-a-time calls, and trees are shared by threads.

mod common;

use obbtree::build::BuildOptions;
use obbtree::bv::BvKind;
use obbtree_c::*;
use std::ffi::{CStr, CString};
use std::path::Path;
use std::ptr::{null, null_mut};

fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated, valid until the next call on this thread.
    unsafe { CStr::from_ptr(obbtree_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// Asserts `status` and that the message contains `needle`.
#[track_caller]
fn fails(status: ObbtreeStatus, expected: ObbtreeStatus, needle: &str) {
    let message = last_error();
    assert_eq!(status, expected, "message: {message}");
    assert!(message.contains(needle), "{needle:?} not in {message:?}");
}

#[track_caller]
fn ok(status: ObbtreeStatus) {
    assert_eq!(status, ObbtreeStatus::Ok, "{}", last_error());
    assert_eq!(last_error(), "", "a success clears the message");
}

fn open(path: &Path) -> *mut ObbtreeTree {
    let path = CString::new(path.to_str().expect("UTF-8 path")).expect("no NUL");
    let mut tree = null_mut();
    // SAFETY: a C string and a writable pointer.
    ok(unsafe { obbtree_open(path.as_ptr(), &mut tree) });
    tree
}

fn translation(x: f64, y: f64, z: f64) -> [f64; 12] {
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, x, y, z]
}

const IDENTITY: [f64; 12] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];

/// The cow's tree, opened, and a pair handle of it with itself.
struct Cow {
    tree: *mut ObbtreeTree,
    pair: *mut ObbtreePair,
    dir: std::path::PathBuf,
}

impl Cow {
    fn new(name: &str) -> Cow {
        let dir = common::scratch(name);
        let tree = open(&common::build_cow(
            &dir,
            "cow.obbt",
            &BuildOptions::default(),
        ));
        let mut pair = null_mut();
        // SAFETY: an open tree and a writable pointer.
        ok(unsafe { obbtree_pair_new(tree, tree, &mut pair) });
        Cow { tree, pair, dir }
    }

    fn collide(
        &self,
        pose_b: &[f64; 12],
        buffer: &mut [ObbtreeTrianglePair],
    ) -> (ObbtreeStatus, ObbtreeCollideResult) {
        let mut out = ObbtreeCollideResult::default();
        // SAFETY: live handle, 12 doubles each, `buffer.len()` writable pairs, a result.
        let status = unsafe {
            obbtree_pair_collide(
                self.pair,
                IDENTITY.as_ptr(),
                pose_b.as_ptr(),
                false,
                if buffer.is_empty() {
                    null_mut()
                } else {
                    buffer.as_mut_ptr()
                },
                buffer.len(),
                &mut out,
            )
        };
        (status, out)
    }
}

impl Drop for Cow {
    fn drop(&mut self) {
        // SAFETY: made by Cow::new, freed once.
        unsafe {
            obbtree_pair_free(self.pair);
            obbtree_close(self.tree);
        }
        std::fs::remove_dir_all(&self.dir).ok();
    }
}

#[test]
fn open_errors_have_codes_and_messages() {
    let dir = common::scratch("open-errors");
    let missing = CString::new(dir.join("missing.obbt").to_str().unwrap()).unwrap();
    let mut tree = std::ptr::dangling_mut::<ObbtreeTree>();
    // SAFETY: a C string and a writable pointer.
    let status = unsafe { obbtree_open(missing.as_ptr(), &mut tree) };
    fails(status, ObbtreeStatus::Io, "missing.obbt");
    assert!(tree.is_null(), "out is NULL on failure");

    let directory = CString::new(dir.to_str().unwrap()).unwrap();
    // SAFETY: as above.
    let status = unsafe { obbtree_open(directory.as_ptr(), &mut tree) };
    fails(status, ObbtreeStatus::Io, "is a directory");

    std::fs::write(dir.join("junk.obbt"), vec![7u8; 4096]).unwrap();
    let junk = CString::new(dir.join("junk.obbt").to_str().unwrap()).unwrap();
    // SAFETY: as above.
    let status = unsafe { obbtree_open(junk.as_ptr(), &mut tree) };
    fails(status, ObbtreeStatus::Format, "not an .obbt file");

    let bytes = [7u8; 300];
    // SAFETY: 300 readable bytes and a writable pointer.
    let status = unsafe { obbtree_open_bytes(bytes.as_ptr(), bytes.len(), &mut tree) };
    fails(status, ObbtreeStatus::Format, "bytes: not an .obbt file");
    // SAFETY: as above, 10 bytes.
    let status = unsafe { obbtree_open_bytes(bytes.as_ptr(), 10, &mut tree) };
    fails(status, ObbtreeStatus::Format, "truncated");

    // SAFETY: NULL arguments are what is tested.
    unsafe {
        fails(
            obbtree_open(null(), &mut tree),
            ObbtreeStatus::NullPointer,
            "path is NULL",
        );
        fails(
            obbtree_open(junk.as_ptr(), null_mut()),
            ObbtreeStatus::NullPointer,
            "out is NULL",
        );
        fails(
            obbtree_open_bytes(null(), 10, &mut tree),
            ObbtreeStatus::NullPointer,
            "data is NULL",
        );
        fails(
            obbtree_verify(null()),
            ObbtreeStatus::NullPointer,
            "tree is NULL",
        );
        let mut info = std::mem::MaybeUninit::<ObbtreeInfo>::uninit();
        fails(
            obbtree_info(null(), info.as_mut_ptr()),
            ObbtreeStatus::NullPointer,
            "tree is NULL",
        );
        // Closing and freeing NULL do nothing.
        obbtree_close(null_mut());
        obbtree_pair_free(null_mut());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn damaged_bytes_open_but_fail_verification() {
    let dir = common::scratch("damaged");
    let path = common::build_cow(&dir, "cow.obbt", &BuildOptions::default());
    let mut bytes = std::fs::read(&path).unwrap();
    let good = bytes.clone();
    // A byte deep in the sections (the header and directory are the first few hundred).
    let at = bytes.len() / 2;
    bytes[at] ^= 0x55;
    let (mut tree, mut intact) = (null_mut(), null_mut());
    // SAFETY: readable bytes (a Vec's, unaligned as any caller's may be) and writable
    // pointers.
    unsafe {
        ok(obbtree_open_bytes(bytes.as_ptr(), bytes.len(), &mut tree));
        fails(obbtree_verify(tree), ObbtreeStatus::Verify, ": ");
        ok(obbtree_open_bytes(good.as_ptr(), good.len(), &mut intact));
        ok(obbtree_verify(intact));
        let mut info = std::mem::MaybeUninit::<ObbtreeInfo>::uninit();
        ok(obbtree_info(intact, info.as_mut_ptr()));
        let info = info.assume_init();
        assert_eq!(info.triangles, 5804);
        assert_eq!(info.file_bytes, good.len() as u64);
        assert_eq!(info.volume, ObbtreeVolume::Obb);
        assert_eq!(CStr::from_ptr(info.volume_name).to_str(), Ok("obb"));
        obbtree_close(tree);
        obbtree_close(intact);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_poses_and_options_are_refused() {
    let cow = Cow::new("bad-poses");
    let mut out = std::mem::MaybeUninit::<ObbtreeDistanceResult>::uninit();
    let distance = |pose_b: &[f64; 12], rel: f64, max: f64, out: *mut ObbtreeDistanceResult| {
        // SAFETY: live handle, 12 doubles each, a writable result.
        unsafe {
            obbtree_pair_distance(
                cow.pair,
                IDENTITY.as_ptr(),
                pose_b.as_ptr(),
                rel,
                0.0,
                max,
                out,
            )
        }
    };
    let mut scaled = translation(2.0, 0.0, 0.0);
    scaled[0] = 2.0;
    fails(
        distance(&scaled, 0.0, f64::INFINITY, out.as_mut_ptr()),
        ObbtreeStatus::Pose,
        "pose_b: rotation is not orthonormal",
    );
    let mut nan = translation(2.0, 0.0, 0.0);
    nan[10] = f64::NAN;
    fails(
        distance(&nan, 0.0, f64::INFINITY, out.as_mut_ptr()),
        ObbtreeStatus::Pose,
        "pose_b: pose value 10 is not finite",
    );
    let mut mirror = translation(2.0, 0.0, 0.0);
    mirror[8] = -1.0;
    fails(
        distance(&mirror, 0.0, f64::INFINITY, out.as_mut_ptr()),
        ObbtreeStatus::Pose,
        "reflection",
    );
    let apart = translation(2.0, 0.0, 0.0);
    fails(
        distance(&apart, -1.0, f64::INFINITY, out.as_mut_ptr()),
        ObbtreeStatus::BadArgument,
        "rel_err",
    );
    fails(
        distance(&apart, 0.0, f64::NAN, out.as_mut_ptr()),
        ObbtreeStatus::BadArgument,
        "max_distance",
    );
    fails(
        distance(&apart, 0.0, f64::INFINITY, null_mut()),
        ObbtreeStatus::NullPointer,
        "out is NULL",
    );
    ok(distance(&apart, 0.0, f64::INFINITY, out.as_mut_ptr()));
    // SAFETY: written by the successful call.
    let d = unsafe { out.assume_init() };
    assert!(
        d.found && d.closest.distance > 0.5 && d.closest.distance < 2.0,
        "{d:?}"
    );
    ok(distance(&apart, 0.0, 0.01, out.as_mut_ptr()));
    // SAFETY: as above.
    let far = unsafe { out.assume_init() };
    assert!(!far.found && far.closest.distance == f64::INFINITY);
    assert_eq!(far.closest.tri_a, OBBTREE_NO_TRIANGLE);

    let mut t = std::mem::MaybeUninit::<ObbtreeToleranceResult>::uninit();
    // SAFETY: live handle, poses, a writable result / NULL where tested.
    unsafe {
        fails(
            obbtree_pair_within(
                cow.pair,
                IDENTITY.as_ptr(),
                apart.as_ptr(),
                -0.5,
                t.as_mut_ptr(),
            ),
            ObbtreeStatus::BadArgument,
            "tolerance",
        );
        fails(
            obbtree_pair_within(cow.pair, null(), apart.as_ptr(), 0.5, t.as_mut_ptr()),
            ObbtreeStatus::NullPointer,
            "pose_a is NULL",
        );
        let mut s = std::mem::MaybeUninit::<ObbtreeSpanResult>::uninit();
        fails(
            obbtree_pair_span(
                null_mut(),
                IDENTITY.as_ptr(),
                apart.as_ptr(),
                s.as_mut_ptr(),
            ),
            ObbtreeStatus::NullPointer,
            "pair is NULL",
        );
        // A misaligned pose pointer is refused, not read.
        let bytes = [0u8; 12 * 8 + 8];
        let odd = bytes.as_ptr().add(1).cast::<f64>();
        fails(
            obbtree_pair_span(cow.pair, odd, apart.as_ptr(), s.as_mut_ptr()),
            ObbtreeStatus::BadArgument,
            "pose_a is not aligned",
        );
    }

    // Checking and repairing poses.
    let mut rounded = [0.0; 12];
    let angle: f64 = 0.3;
    let r = [
        angle.cos(),
        -angle.sin(),
        0.0,
        angle.sin(),
        angle.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    for (k, v) in r.iter().enumerate() {
        rounded[k] = (v * 1000.0).round() / 1000.0;
    }
    let mut repaired = [0.0; 12];
    // SAFETY: 12 doubles each.
    unsafe {
        fails(
            obbtree_pose_check(rounded.as_ptr()),
            ObbtreeStatus::Pose,
            "not orthonormal",
        );
        ok(obbtree_pose_orthonormalize(
            rounded.as_ptr(),
            repaired.as_mut_ptr(),
        ));
        ok(obbtree_pose_check(repaired.as_ptr()));
        fails(
            obbtree_pose_orthonormalize(scaled.as_ptr(), repaired.as_mut_ptr()),
            ObbtreeStatus::Pose,
            "scaled or sheared",
        );
    }
}

#[test]
fn a_short_buffer_reports_the_size_needed() {
    let cow = Cow::new("short-buffer");
    let touching = translation(0.3, 0.0, 0.0);
    let (status, counted) = cow.collide(&touching, &mut []);
    ok(status);
    let needed = counted.pair_count;
    assert!(
        needed > 3,
        "the cow touches itself in many places: {needed}"
    );
    let mut full = vec![ObbtreeTrianglePair::default(); needed];
    let (status, all) = cow.collide(&touching, &mut full);
    ok(status);
    assert_eq!(all, counted);
    let mut short = vec![ObbtreeTrianglePair::default(); 3];
    let (status, partial) = cow.collide(&touching, &mut short);
    fails(
        status,
        ObbtreeStatus::BufferTooSmall,
        &format!("holds 3 pairs but {needed} are needed"),
    );
    assert_eq!(partial.pair_count, needed);
    assert!(partial.colliding);
    assert_eq!(short[..], full[..3], "the first pairs are written");
    // A NULL buffer with a capacity is an error, not a crash.
    let mut out = ObbtreeCollideResult::default();
    // SAFETY: live handle, poses, a result; the NULL buffer is what is tested.
    let status = unsafe {
        obbtree_pair_collide(
            cow.pair,
            IDENTITY.as_ptr(),
            touching.as_ptr(),
            false,
            null_mut(),
            5,
            &mut out,
        )
    };
    fails(status, ObbtreeStatus::NullPointer, "pairs is NULL");

    // Batches: the total needed, every result complete.
    let poses = [
        translation(0.3, 0.0, 0.0),
        translation(2.0, 0.0, 0.0),
        translation(0.1, 0.0, 0.0),
    ];
    let mut results = [ObbtreeCollideResult::default(); 3];
    let mut buffer = vec![ObbtreeTrianglePair::default(); needed];
    let mut total = 0usize;
    // SAFETY: open trees, 1 and 3 poses, 3 results, `needed` pairs, a total.
    let status = unsafe {
        obbtree_collide_batch(
            cow.tree,
            IDENTITY.as_ptr(),
            1,
            cow.tree,
            poses.as_ptr().cast(),
            3,
            false,
            0,
            results.as_mut_ptr(),
            3,
            buffer.as_mut_ptr(),
            buffer.len(),
            &mut total,
        )
    };
    fails(status, ObbtreeStatus::BufferTooSmall, "are needed");
    assert_eq!(results[0].pair_count, needed);
    assert_eq!(results[1].pair_count, 0);
    assert_eq!(results[2].pair_offset, needed);
    assert_eq!(total, needed + results[2].pair_count);
    assert_eq!(buffer, full, "the first pose's pairs fit and are written");
}

#[test]
fn batch_arguments_are_checked_and_batches_equal_single_calls() {
    let cow = Cow::new("batch");
    let poses: Vec<[f64; 12]> = (0..8)
        .map(|k| translation(0.25 * k as f64, 0.1, 0.0))
        .collect();
    let mut results = vec![
        ObbtreeDistanceResult {
            found: false,
            closest: ObbtreeWitness {
                distance: 0.0,
                point_a: [0.0; 3],
                point_b: [0.0; 3],
                tri_a: 0,
                tri_b: 0,
            },
            work: ObbtreeWork::default(),
        };
        8
    ];
    let batch = |count_a: usize,
                 poses_b: &[[f64; 12]],
                 count_b: usize,
                 threads: usize,
                 results: &mut [ObbtreeDistanceResult],
                 len: usize| {
        let repeated: Vec<[f64; 12]> = vec![IDENTITY; count_a.max(1)];
        // SAFETY: open trees, `count` poses each (the slices hold at least that many),
        // `len` results (at most results.len(), as the callers pass).
        unsafe {
            obbtree_distance_batch(
                cow.tree,
                repeated.as_ptr().cast(),
                count_a,
                cow.tree,
                poses_b.as_ptr().cast(),
                count_b,
                0.0,
                0.0,
                f64::INFINITY,
                threads,
                results.as_mut_ptr(),
                len,
            )
        }
    };
    fails(
        batch(3, &poses, 8, 0, &mut results, 8),
        ObbtreeStatus::BadArgument,
        "count_a is 3 and count_b is 8",
    );
    fails(
        batch(1, &poses, 8, 0, &mut results, 7),
        ObbtreeStatus::BadArgument,
        "results_len is 7",
    );
    fails(
        batch(1, &poses, 8, 100_000, &mut results, 8),
        ObbtreeStatus::BadArgument,
        "threads is 100000: at most 1024",
    );
    let mut bad = poses.clone();
    bad[5][4] = 3.0;
    fails(
        batch(1, &bad, 8, 0, &mut results, 8),
        ObbtreeStatus::Pose,
        "poses_b[5]: rotation is not orthonormal",
    );
    // SAFETY: NULL trees and poses are what is tested.
    unsafe {
        fails(
            obbtree_span_batch(
                cow.tree,
                IDENTITY.as_ptr(),
                1,
                cow.tree,
                IDENTITY.as_ptr(),
                1,
                0,
                null_mut(),
                0,
            ),
            ObbtreeStatus::BadArgument,
            "results_len is 0",
        );
        let mut span = [ObbtreeSpanResult {
            farthest: results[0].closest,
            work: ObbtreeWork::default(),
        }; 1];
        fails(
            obbtree_span_batch(
                null(),
                IDENTITY.as_ptr(),
                1,
                cow.tree,
                IDENTITY.as_ptr(),
                1,
                0,
                span.as_mut_ptr(),
                1,
            ),
            ObbtreeStatus::NullPointer,
            "a is NULL",
        );
        fails(
            obbtree_span_batch(
                cow.tree,
                null(),
                1,
                cow.tree,
                IDENTITY.as_ptr(),
                1,
                0,
                span.as_mut_ptr(),
                1,
            ),
            ObbtreeStatus::NullPointer,
            "poses_a is NULL",
        );
    }
    // Broadcast on either side, any thread count: the same answers as one call per pose.
    for threads in [0, 1, 3] {
        ok(batch(1, &poses, 8, threads, &mut results, 8));
        for (pose, batched) in poses.iter().zip(&results) {
            let mut single = std::mem::MaybeUninit::<ObbtreeDistanceResult>::uninit();
            // SAFETY: live handle, poses, a result.
            ok(unsafe {
                obbtree_pair_distance(
                    cow.pair,
                    IDENTITY.as_ptr(),
                    pose.as_ptr(),
                    0.0,
                    0.0,
                    f64::INFINITY,
                    single.as_mut_ptr(),
                )
            });
            // SAFETY: written by the successful call.
            assert_eq!(unsafe { single.assume_init() }, *batched);
        }
    }
    let mut equal_counts = results.clone();
    ok(batch(8, &poses, 8, 2, &mut equal_counts, 8));
    assert_eq!(equal_counts, results);
    ok(batch(0, &poses, 0, 0, &mut [], 0));
}

#[test]
fn mismatched_trees_are_refused() {
    let dir = common::scratch("mismatched");
    let obb = open(&common::build_cow(
        &dir,
        "obb.obbt",
        &BuildOptions::default(),
    ));
    let aabb_options = BuildOptions {
        bv: BvKind::Aabb,
        ..BuildOptions::default()
    };
    let aabb = open(&common::build_cow(&dir, "aabb.obbt", &aabb_options));
    let mut pair = std::ptr::dangling_mut::<ObbtreePair>();
    let mut result = [ObbtreeCollideResult::default()];
    // SAFETY: open trees, writable outputs, 1 pose each.
    unsafe {
        fails(
            obbtree_pair_new(obb, aabb, &mut pair),
            ObbtreeStatus::MismatchedTrees,
            "A stores obb f32, B stores aabb f32",
        );
        assert!(pair.is_null());
        fails(
            obbtree_collide_batch(
                obb,
                IDENTITY.as_ptr(),
                1,
                aabb,
                IDENTITY.as_ptr(),
                1,
                true,
                0,
                result.as_mut_ptr(),
                1,
                null_mut(),
                0,
                null_mut(),
            ),
            ObbtreeStatus::MismatchedTrees,
            "differ in kind",
        );
        obbtree_close(obb);
        obbtree_close(aabb);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn threads_share_a_tree_and_a_pair_outlives_its_closed_tree() {
    let cow = Cow::new("threads");
    let poses: Vec<[f64; 12]> = (0..16)
        .map(|k| translation(0.1 * k as f64, 0.05, 0.0))
        .collect();
    let span = |pair: *mut ObbtreePair, pose: &[f64; 12]| {
        let mut out = std::mem::MaybeUninit::<ObbtreeSpanResult>::uninit();
        // SAFETY: a live handle used by this thread only, poses, a result.
        ok(unsafe { obbtree_pair_span(pair, IDENTITY.as_ptr(), pose.as_ptr(), out.as_mut_ptr()) });
        // SAFETY: written by the successful call.
        unsafe { out.assume_init() }
    };
    let want: Vec<_> = poses.iter().map(|p| span(cow.pair, p)).collect();
    /// The tree pointer, sent to threads (the tree is Sync).
    #[derive(Clone, Copy)]
    struct Shared(*mut ObbtreeTree);
    // SAFETY: an ObbtreeTree is read-only and its file is Sync.
    unsafe impl Send for Shared {}
    let shared = Shared(cow.tree);
    std::thread::scope(|scope| {
        for _ in 0..4 {
            let (poses, want) = (&poses, &want);
            scope.spawn(move || {
                let shared = shared;
                let mut pair = null_mut();
                // SAFETY: an open tree, a writable pointer.
                ok(unsafe { obbtree_pair_new(shared.0, shared.0, &mut pair) });
                for (pose, want) in poses.iter().zip(want) {
                    assert_eq!(span(pair, pose), *want);
                }
                // SAFETY: made above, freed once.
                unsafe { obbtree_pair_free(pair) };
            });
        }
    });

    // A pair keeps its trees mapped after they are closed.
    let dir = common::scratch("outlives");
    let tree = open(&common::build_cow(
        &dir,
        "cow.obbt",
        &BuildOptions::default(),
    ));
    let mut pair = null_mut();
    // SAFETY: an open tree, then closed while the handle lives; the handle freed once.
    unsafe {
        ok(obbtree_pair_new(tree, tree, &mut pair));
        obbtree_close(tree);
        assert_eq!(span(pair, &poses[3]), want[3]);
        obbtree_pair_free(pair);
    }
    std::fs::remove_dir_all(&dir).ok();
}
