//! The C API of obbtree: open `.obbt` trees (memory-mapped from a path, or from bytes in
//! memory), verify them, read what their header says, and run collision, distance,
//! tolerance and span queries between two posed trees, one pose pair at a time through a
//! reusable pair handle or a whole batch of poses in one parallel call, and cast rays,
//! find closest points and winding numbers of one posed tree for batches of rays or points.
//!
//! The header `include/obbtree.h` is generated from this file by cbindgen (see the README);
//! a test fails when the committed header differs from what this source generates.
//!
//! Conventions of every entry point:
//!
//! - it returns an `ObbtreeStatus`; on any status but `OBBTREE_STATUS_OK`,
//!   `obbtree_last_error` gives a one-line message (the CLI's wording for the same error);
//! - no Rust panic crosses the boundary: an internal error becomes
//!   `OBBTREE_STATUS_INTERNAL_ERROR`;
//! - null or misaligned pointers, counts that do not fit and out-of-range options are
//!   refused with an error code before anything is read or written;
//! - a pose is 12 `double`s: the rotation row by row, then the translation
//!   (`world = R p + t`); it must be rigid (orthonormal within 1e-6, determinant +1, every
//!   number finite), as the CLI requires, and a rotation within the tolerance is used as
//!   its nearest rotation.
//!
//! Threads: an `ObbtreeTree` may be used by any number of threads at once. An
//! `ObbtreePair` is used by one thread at a time (it holds the traversal scratch); a
//! second thread calling into a handle in use gets `OBBTREE_STATUS_BUSY`, never a race.
#![deny(
    unsafe_op_in_unsafe_fn,
    missing_docs,
    clippy::undocumented_unsafe_blocks
)]

use obbtree::bv::{BvKind, Layout};
use obbtree::fit::FitMethod;
use obbtree::format::{AlignedBytes, ObbtFile, OpenError, VerifyError};
use obbtree::query::{
    batch, BatchError, BatchOptions, CollideOptions, CollideResult, DistanceOptions,
    DistanceResult, PairQuery, Pose, PoseBatch, PoseError, PoseFormat, QueryError, SpanOptions,
    SpanResult, ToleranceOptions, ToleranceResult, Witness, Work,
};
use obbtree::real::Precision;
use obbtree::tree::Encoding;
use rayon::prelude::*;
use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::mem::MaybeUninit;
use std::num::NonZeroUsize;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex, TryLockError};

mod contacts;
mod hausdorff;
mod model;
pub use contacts::*;
pub use hausdorff::*;
pub use model::*;

// ---------------------------------------------------------------------------------------
// Types seen from C
// ---------------------------------------------------------------------------------------

/// What a call did: `OBBTREE_STATUS_OK`, or why it failed (then `obbtree_last_error` says
/// more).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObbtreeStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument is NULL.
    NullPointer = 1,
    /// An argument is out of range: a count, a misaligned pointer, a negative or
    /// non-finite option, batch sizes that do not match, a path that is not valid text.
    BadArgument = 2,
    /// The operating system refused to open or map the file.
    Io = 3,
    /// The bytes are not a valid `.obbt` header and section directory.
    Format = 4,
    /// `obbtree_verify` found damage in the sections.
    Verify = 5,
    /// A pose is not a rigid motion (not finite, not orthonormal, a reflection).
    Pose = 6,
    /// The two trees store different volume types, precisions or layouts.
    MismatchedTrees = 7,
    /// A tree's nodes are inconsistent (a damaged file that was not verified).
    CorruptTree = 8,
    /// The caller's pair buffer is too short: the results are complete, the buffer holds
    /// the first `capacity` pairs, and the number needed is reported.
    BufferTooSmall = 9,
    /// Another thread is using this pair handle right now.
    Busy = 10,
    /// A bug in obbtree (a Rust panic, caught at the boundary); the message says where.
    InternalError = 11,
}

/// An open `.obbt` tree (opaque). Made by `obbtree_open` or `obbtree_open_bytes`,
/// released by `obbtree_close`. Read-only: any number of threads may query one tree at
/// once.
pub struct ObbtreeTree {
    file: Arc<ObbtFile>,
}

/// Two trees checked to be queryable together, with the traversal scratch kept between
/// queries (opaque). Made by `obbtree_pair_new`, released by `obbtree_pair_free`. One
/// thread at a time: a handle may move between threads, but a call made while another
/// thread is inside a call on the same handle returns `OBBTREE_STATUS_BUSY`. Give each
/// thread its own handle.
pub struct ObbtreePair {
    // Declared before the files so that it is dropped before them: it borrows them.
    state: Mutex<PairState>,
    _a: Arc<ObbtFile>,
    _b: Arc<ObbtFile>,
}

/// What a pair handle keeps between queries.
struct PairState {
    query: PairQuery<'static>,
    /// The collision result buffer, reused so that a query per frame allocates nothing.
    collide: CollideResult,
}

/// Triangle id of a result without a triangle (a distance beyond `max_distance`, a
/// tolerance query with no pair closer than the tolerance).
pub const OBBTREE_NO_TRIANGLE: u32 = u32::MAX;

/// The most threads a batch call starts for itself (a larger `threads` is an error rather
/// than an attempt to start that many).
pub const OBBTREE_MAX_THREADS: usize = 1024;

/// The bounding volume type a tree stores (the values are the file's header tags).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObbtreeVolume {
    /// Oriented bounding boxes.
    Obb = 1,
    /// Axis-aligned bounding boxes (in the model frame).
    Aabb = 2,
    /// Bounding spheres.
    Sphere = 3,
}

/// The precision a tree stores its numbers in (the values are bytes per number).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObbtreePrecision {
    /// 32-bit floats.
    F32 = 4,
    /// 64-bit floats.
    F64 = 8,
}

/// What a tree's header says (`obbtree info`), read without touching the sections.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct ObbtreeInfo {
    /// Format version, major part.
    pub version_major: u16,
    /// Format version, minor part.
    pub version_minor: u16,
    /// Bounding volume type.
    pub volume: ObbtreeVolume,
    /// Stored precision.
    pub precision: ObbtreePrecision,
    /// `"obb"`, `"aabb"` or `"sphere"` (static string).
    pub volume_name: *const c_char,
    /// `"f32"` or `"f64"` (static string).
    pub precision_name: *const c_char,
    /// How the volumes were fitted: `"hull"`, `"triangles"` or `"vertices"` (static string).
    pub fit_name: *const c_char,
    /// Node encoding: `"binary"` or `"variable"` (static string).
    pub encoding_name: *const c_char,
    /// Triangle count.
    pub triangles: u32,
    /// Vertex count.
    pub vertices: u32,
    /// Node count.
    pub nodes: u32,
    /// Leaf count.
    pub leaves: u32,
    /// Depth of the tree (a root alone has depth 0).
    pub depth: u32,
    /// Most faces in one leaf.
    pub max_leaf_faces: u32,
    /// The leaf size the tree was built with.
    pub leaf_size: u32,
    /// Triangles of zero area.
    pub degenerate_triangles: u32,
    /// Smallest corner of the vertices' bounding box, in stored units (see `placement_*`).
    pub bounds_min: [f64; 3],
    /// Largest corner of the vertices' bounding box, in stored units.
    pub bounds_max: [f64; 3],
    /// Stored units per input unit: `stored = placement_scale * input + placement_offset`.
    pub placement_scale: f64,
    /// Added after scaling, stored units.
    pub placement_offset: [f64; 3],
    /// File length in bytes.
    pub file_bytes: u64,
    /// Node layout: `"fast"` or `"compact"` (quantised boxes; static string). Last, so the
    /// fields before it keep their offsets from earlier versions.
    pub layout_name: *const c_char,
}

/// Work a query did (the dissertation's counts, §2.5.1).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObbtreeWork {
    /// Bounding-volume pair tests that pruned the pair.
    pub bv_disjoint: u64,
    /// Bounding-volume pair tests that did not prune.
    pub bv_overlap: u64,
    /// Triangle pair tests whose triangles do not touch.
    pub tri_separated: u64,
    /// Triangle pair tests whose triangles touch.
    pub tri_contact: u64,
    /// Node pairs the traversal decided on.
    pub nodes_visited: u64,
}

/// A contacting triangle pair: input-mesh triangle ids of A and of B.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObbtreeTrianglePair {
    /// Triangle of A.
    pub tri_a: u32,
    /// Triangle of B.
    pub tri_b: u32,
}

/// A triangle of A and one of B with the distance between them and the points realising
/// it (world frame). Without a pair (see the result's flag) the distance is +infinity, the
/// points are NaN and the triangles are `OBBTREE_NO_TRIANGLE`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeWitness {
    /// Distance between `point_a` and `point_b`, world units.
    pub distance: f64,
    /// The point on A, world frame.
    pub point_a: [f64; 3],
    /// The point on B, world frame.
    pub point_b: [f64; 3],
    /// Input-mesh id of A's triangle holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of B's triangle holding `point_b`.
    pub tri_b: u32,
}

/// The answer of a collision query.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObbtreeCollideResult {
    /// 1 when any triangle of A touches any triangle of B.
    pub colliding: bool,
    /// Contacting triangle pairs (at most 1 with `first_contact`).
    pub pair_count: usize,
    /// Where this answer's pairs start in the pairs buffer (0 for a single query; in a
    /// batch, the pairs of all poses follow each other in pose order).
    pub pair_offset: usize,
    /// Work done.
    pub work: ObbtreeWork,
}

/// The answer of a distance query.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeDistanceResult {
    /// 0 when the models are at least `max_distance` apart (then `closest.distance` is
    /// +infinity), 1 otherwise.
    pub found: bool,
    /// The closest pair (distance 0 when the surfaces touch).
    pub closest: ObbtreeWitness,
    /// Work done.
    pub work: ObbtreeWork,
}

/// The answer of a tolerance query.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeToleranceResult {
    /// 1 when the surfaces come closer than the tolerance.
    pub closer: bool,
    /// With `closer`: a pair closer than the tolerance (not necessarily the closest).
    pub witness: ObbtreeWitness,
    /// Work done.
    pub work: ObbtreeWork,
}

/// The answer of a span query.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeSpanResult {
    /// The farthest pair: `farthest.distance` is the span, the largest distance between a
    /// point of A and a point of B.
    pub farthest: ObbtreeWitness,
    /// Work done.
    pub work: ObbtreeWork,
}

// ---------------------------------------------------------------------------------------
// Errors, the last-error message and the panic guard
// ---------------------------------------------------------------------------------------

/// A failed call: its status and message.
#[derive(Debug)]
struct Error {
    status: ObbtreeStatus,
    message: String,
}

impl Error {
    fn new(status: ObbtreeStatus, message: impl Into<String>) -> Error {
        Error {
            status,
            message: message.into(),
        }
    }

    fn null(name: &str) -> Error {
        Error::new(ObbtreeStatus::NullPointer, format!("{name} is NULL"))
    }

    fn bad(message: impl Into<String>) -> Error {
        Error::new(ObbtreeStatus::BadArgument, message)
    }

    fn pose(what: &str, e: PoseError) -> Error {
        Error::new(ObbtreeStatus::Pose, format!("{what}: {e}"))
    }
}

impl From<OpenError> for Error {
    fn from(e: OpenError) -> Error {
        let status = match e {
            OpenError::Io { .. } => ObbtreeStatus::Io,
            _ => ObbtreeStatus::Format,
        };
        Error::new(status, e.to_string())
    }
}

impl From<VerifyError> for Error {
    fn from(e: VerifyError) -> Error {
        Error::new(ObbtreeStatus::Verify, e.to_string())
    }
}

impl From<QueryError> for Error {
    fn from(e: QueryError) -> Error {
        let status = match e {
            QueryError::MismatchedTrees { .. } => ObbtreeStatus::MismatchedTrees,
            QueryError::BadOption { .. } | QueryError::BadInput { .. } => {
                ObbtreeStatus::BadArgument
            }
            QueryError::Format(_) => ObbtreeStatus::Format,
            _ => ObbtreeStatus::CorruptTree,
        };
        Error::new(status, e.to_string())
    }
}

impl From<BatchError> for Error {
    fn from(e: BatchError) -> Error {
        match e {
            BatchError::Pair(e) => Error::from(e),
            BatchError::Threads { ref source, .. } => {
                Error::new(ObbtreeStatus::InternalError, format!("{e}: {source}"))
            }
            other => Error::new(ObbtreeStatus::InternalError, other.to_string()),
        }
    }
}

thread_local! {
    /// The message of this thread's latest call, `None` after a success (so that a
    /// successful call allocates nothing for it).
    static LAST_ERROR: RefCell<Option<CString>> = const { RefCell::new(None) };
}

/// Records `message` as this thread's last error (NUL bytes, which C strings cannot hold,
/// become `\0`), or clears it for `None`.
fn set_last_error(message: Option<&str>) {
    let text = message.map(|m| CString::new(m.replace('\0', "\\0")).unwrap_or_default());
    // Fails only while the thread is being torn down, when nobody can read it any more.
    let _ = LAST_ERROR.try_with(|last| {
        if text.is_some() || last.borrow().is_some() {
            last.replace(text);
        }
    });
}

/// Runs the body of an entry point: its error becomes a status and this thread's last
/// error message, a success clears the message, and a panic is caught here so that it never
/// unwinds into C.
fn guard(body: impl FnOnce() -> Result<(), Error>) -> ObbtreeStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => {
            set_last_error(None);
            ObbtreeStatus::Ok
        }
        Ok(Err(e)) => {
            set_last_error(Some(&e.message));
            e.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(Some(&format!(
                "internal error in obbtree (please report it): {what}"
            )));
            ObbtreeStatus::InternalError
        }
    }
}

/// Runs `body` (an entry point returning a value rather than a status), or returns
/// `fallback` if it panics.
fn guard_value<T>(fallback: T, body: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(body)).unwrap_or(fallback)
}

// ---------------------------------------------------------------------------------------
// Checked pointer access
// ---------------------------------------------------------------------------------------

/// Refuses a NULL or misaligned pointer.
fn check_ptr<T>(ptr: *const T, name: &str) -> Result<(), Error> {
    if ptr.is_null() {
        return Err(Error::null(name));
    }
    if !ptr.is_aligned() {
        return Err(Error::bad(format!(
            "{name} is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    Ok(())
}

/// `*ptr`, after the checks C callers can get wrong and we can see.
///
/// # Safety
///
/// A non-NULL `ptr` points at a live `T` that nothing writes during `'a`.
unsafe fn deref<'a, T>(ptr: *const T, name: &str) -> Result<&'a T, Error> {
    check_ptr(ptr, name)?;
    // SAFETY: non-NULL and aligned (checked above); live and unchanged for 'a (the caller).
    Ok(unsafe { &*ptr })
}

/// Refuses a length whose bytes exceed what one Rust slice may span.
fn check_len<T>(len: usize, name: &str) -> Result<(), Error> {
    match len.checked_mul(std::mem::size_of::<T>()) {
        Some(bytes) if bytes <= isize::MAX as usize => Ok(()),
        _ => Err(Error::bad(format!("{name}: count {len} is too large"))),
    }
}

/// `len` values at `ptr` (any pointer, even NULL, for `len` 0).
///
/// # Safety
///
/// For `len > 0`, a non-NULL `ptr` points at `len` live `T`s that nothing writes during
/// `'a`.
unsafe fn slice<'a, T>(ptr: *const T, len: usize, name: &str) -> Result<&'a [T], Error> {
    if len == 0 {
        return Ok(&[]);
    }
    check_ptr(ptr, name)?;
    check_len::<T>(len, name)?;
    // SAFETY: non-NULL, aligned, and the byte length fits an isize (checked above); `len`
    // live values, unchanged for 'a (the caller).
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// `len` writable slots at `ptr`, possibly uninitialised (any pointer, even NULL, for
/// `len` 0).
///
/// # Safety
///
/// For `len > 0`, a non-NULL `ptr` points at `len` writable `T`s that nothing else reads
/// or writes during `'a`.
unsafe fn slots<'a, T>(
    ptr: *mut T,
    len: usize,
    name: &str,
) -> Result<&'a mut [MaybeUninit<T>], Error> {
    if len == 0 {
        return Ok(&mut []);
    }
    check_ptr(ptr, name)?;
    check_len::<T>(len, name)?;
    // SAFETY: as in `slice`, and exclusive for 'a (the caller); MaybeUninit<T> has T's
    // layout and makes no claim that the slots are initialised.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr.cast::<MaybeUninit<T>>(), len) })
}

/// One output slot at `ptr`.
///
/// # Safety
///
/// A non-NULL `ptr` points at a writable `T` that nothing else reads or writes during
/// `'a`.
unsafe fn slot<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut MaybeUninit<T>, Error> {
    check_ptr(ptr, name)?;
    // SAFETY: non-NULL and aligned (checked); writable and exclusive for 'a (the caller).
    Ok(unsafe { &mut *ptr.cast::<MaybeUninit<T>>() })
}

/// The pose of 12 numbers at `ptr`, checked to be rigid.
///
/// # Safety
///
/// A non-NULL `ptr` points at 12 readable doubles.
unsafe fn read_pose(ptr: *const f64, name: &str) -> Result<Pose, Error> {
    // SAFETY: forwarded from the caller.
    let values = unsafe { slice(ptr, 12, name) }?;
    Pose::from_row_major(values).map_err(|e| Error::pose(name, e))
}

// ---------------------------------------------------------------------------------------
// Conversions to the C structs
// ---------------------------------------------------------------------------------------

fn work(w: &Work) -> ObbtreeWork {
    ObbtreeWork {
        bv_disjoint: w.bv_disjoint,
        bv_overlap: w.bv_overlap,
        tri_separated: w.tri_separated,
        tri_contact: w.tri_contact,
        nodes_visited: w.nodes_visited,
    }
}

fn witness(w: Option<&Witness>) -> ObbtreeWitness {
    match w {
        Some(w) => ObbtreeWitness {
            distance: w.distance,
            point_a: w.point_a.into(),
            point_b: w.point_b.into(),
            tri_a: w.tri_a,
            tri_b: w.tri_b,
        },
        None => ObbtreeWitness {
            distance: f64::INFINITY,
            point_a: [f64::NAN; 3],
            point_b: [f64::NAN; 3],
            tri_a: OBBTREE_NO_TRIANGLE,
            tri_b: OBBTREE_NO_TRIANGLE,
        },
    }
}

// A query's result as C reads it, one conversion per kind for the single and batch calls.

impl From<&DistanceResult> for ObbtreeDistanceResult {
    fn from(r: &DistanceResult) -> ObbtreeDistanceResult {
        ObbtreeDistanceResult {
            found: r.closest.is_some(),
            closest: witness(r.closest.as_ref()),
            work: work(&r.work),
        }
    }
}

impl From<&ToleranceResult> for ObbtreeToleranceResult {
    fn from(r: &ToleranceResult) -> ObbtreeToleranceResult {
        ObbtreeToleranceResult {
            closer: r.witness.is_some(),
            witness: witness(r.witness.as_ref()),
            work: work(&r.work),
        }
    }
}

impl From<&SpanResult> for ObbtreeSpanResult {
    fn from(r: &SpanResult) -> ObbtreeSpanResult {
        ObbtreeSpanResult {
            farthest: witness(Some(&r.farthest)),
            work: work(&r.work),
        }
    }
}

fn volume(kind: BvKind) -> (ObbtreeVolume, &'static CStr) {
    match kind {
        BvKind::Obb => (ObbtreeVolume::Obb, c"obb"),
        BvKind::Aabb => (ObbtreeVolume::Aabb, c"aabb"),
        BvKind::Sphere => (ObbtreeVolume::Sphere, c"sphere"),
    }
}

fn precision(p: Precision) -> (ObbtreePrecision, &'static CStr) {
    match p {
        Precision::F32 => (ObbtreePrecision::F32, c"f32"),
        Precision::F64 => (ObbtreePrecision::F64, c"f64"),
    }
}

fn fit_name(fit: FitMethod) -> &'static CStr {
    match fit {
        FitMethod::Hull => c"hull",
        FitMethod::Triangles => c"triangles",
        FitMethod::Vertices => c"vertices",
    }
}

fn encoding_name(encoding: Encoding) -> &'static CStr {
    match encoding {
        Encoding::Binary => c"binary",
        Encoding::Variable => c"variable",
    }
}

fn layout_name(layout: Layout) -> &'static CStr {
    match layout {
        Layout::Fast => c"fast",
        Layout::Compact => c"compact",
    }
}

// ---------------------------------------------------------------------------------------
// Library, errors
// ---------------------------------------------------------------------------------------

/// The version of this library, e.g. `"0.1.0"` (static string).
#[no_mangle]
pub extern "C" fn obbtree_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The message of this thread's latest obbtree call: one line saying what failed, or `""`
/// when that call succeeded. Never NULL. The string belongs to the library and stays valid
/// until the next obbtree call on the same thread; copy it to keep it.
#[no_mangle]
pub extern "C" fn obbtree_last_error() -> *const c_char {
    guard_value(c"".as_ptr(), || {
        LAST_ERROR
            .try_with(|last| last.borrow().as_deref().map_or(c"".as_ptr(), CStr::as_ptr))
            .unwrap_or(c"".as_ptr())
    })
}

/// The name of a status code, e.g. `"OBBTREE_STATUS_POSE"` (static string; `"unknown"`
/// for a value that is not a status).
#[no_mangle]
pub extern "C" fn obbtree_status_name(status: i32) -> *const c_char {
    let name = match status {
        0 => c"OBBTREE_STATUS_OK",
        1 => c"OBBTREE_STATUS_NULL_POINTER",
        2 => c"OBBTREE_STATUS_BAD_ARGUMENT",
        3 => c"OBBTREE_STATUS_IO",
        4 => c"OBBTREE_STATUS_FORMAT",
        5 => c"OBBTREE_STATUS_VERIFY",
        6 => c"OBBTREE_STATUS_POSE",
        7 => c"OBBTREE_STATUS_MISMATCHED_TREES",
        8 => c"OBBTREE_STATUS_CORRUPT_TREE",
        9 => c"OBBTREE_STATUS_BUFFER_TOO_SMALL",
        10 => c"OBBTREE_STATUS_BUSY",
        11 => c"OBBTREE_STATUS_INTERNAL_ERROR",
        _ => c"unknown",
    };
    name.as_ptr()
}

// ---------------------------------------------------------------------------------------
// Trees
// ---------------------------------------------------------------------------------------

/// Hands a tree to C.
fn new_tree(file: ObbtFile, out: &mut MaybeUninit<*mut ObbtreeTree>) {
    let tree = Box::new(ObbtreeTree {
        file: Arc::new(file),
    });
    out.write(Box::into_raw(tree));
}

/// Opens the `.obbt` file at `path` (a NUL-terminated path in the system's encoding; UTF-8
/// on Windows): memory-maps it and checks its header and directory, in constant time for
/// any size. Does not check the sections: call `obbtree_verify` for a file from
/// elsewhere. On success `*out` is the tree, to be released with `obbtree_close`; on
/// failure `*out` is NULL (`OBBTREE_STATUS_IO`, `OBBTREE_STATUS_FORMAT`).
///
/// Do not modify the file in place while it is open (replacing it by renaming another file
/// over it, as obbtree's own writer does, is fine).
///
/// # Safety
///
/// `path` is NULL or a NUL-terminated string; `out` is NULL or points at writable storage
/// for one pointer.
#[no_mangle]
pub unsafe extern "C" fn obbtree_open(
    path: *const c_char,
    out: *mut *mut ObbtreeTree,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: `out` is writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        out.write(std::ptr::null_mut());
        check_ptr(path, "path")?;
        // SAFETY: non-NULL (checked) and NUL-terminated (the caller's contract).
        let path = unsafe { CStr::from_ptr(path) };
        #[cfg(unix)]
        let path = {
            use std::os::unix::ffi::OsStrExt;
            std::path::Path::new(std::ffi::OsStr::from_bytes(path.to_bytes()))
        };
        #[cfg(not(unix))]
        let path = std::path::Path::new(
            path.to_str()
                .map_err(|_| Error::bad("path is not valid UTF-8"))?,
        );
        new_tree(ObbtFile::open(path)?, out);
        Ok(())
    })
}

/// Opens a tree from `len` bytes at `data`: a whole `.obbt` image in memory, for example an
/// asset embedded in the executable. The bytes are copied into a 64-byte aligned buffer
/// owned by the tree (the library views sections in place, which needs that alignment),
/// so `data` may have any alignment and may be freed as soon as this returns. The
/// header and directory are checked as by `obbtree_open`; on success `*out` is the tree,
/// to be released with `obbtree_close`, on failure NULL (`OBBTREE_STATUS_FORMAT`).
///
/// # Safety
///
/// `data` is NULL or points at `len` readable bytes; `out` is NULL or points at writable
/// storage for one pointer.
#[no_mangle]
pub unsafe extern "C" fn obbtree_open_bytes(
    data: *const u8,
    len: usize,
    out: *mut *mut ObbtreeTree,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: `out` is writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        out.write(std::ptr::null_mut());
        check_ptr(data, "data")?;
        // SAFETY: `len` readable bytes at `data` (the caller's contract).
        let bytes = unsafe { slice(data, len, "data") }?;
        let file = ObbtFile::from_aligned(AlignedBytes::copy_from(bytes))
            .map_err(|e| Error::new(ObbtreeStatus::Format, format!("bytes: {e}")))?;
        new_tree(file, out);
        Ok(())
    })
}

/// Releases a tree. Pair handles made from it stay valid (they keep what they need); the
/// file is unmapped when the last of them is freed. NULL is ignored.
///
/// # Safety
///
/// `tree` is NULL or a tree from `obbtree_open` / `obbtree_open_bytes` not yet closed;
/// no other thread is using it, and it is not used after this call.
#[no_mangle]
pub unsafe extern "C" fn obbtree_close(tree: *mut ObbtreeTree) {
    if tree.is_null() {
        return;
    }
    // SAFETY: the pointer came from Box::into_raw in `new_tree` and is given back once (the
    // caller's contract). Dropping an Arc and a map cannot panic, so no guard is needed; one
    // is used anyway so that nothing can unwind into C.
    let tree = unsafe { Box::from_raw(tree) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(tree)));
}

/// Runs the O(n) checks of the format on `tree`: section checksums, padding, indices in
/// bounds, a well-formed tree, finite values, and every volume containing the vertices
/// below it. `OBBTREE_STATUS_VERIFY` with the first problem found when damaged. Run it once
/// on a file that came from elsewhere: queries on a damaged, unverified file give
/// `OBBTREE_STATUS_CORRUPT_TREE` or wrong answers, never undefined behaviour.
///
/// # Safety
///
/// `tree` is NULL or an open tree.
#[no_mangle]
pub unsafe extern "C" fn obbtree_verify(tree: *const ObbtreeTree) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or an open tree (the caller's contract).
        let tree = unsafe { deref(tree, "tree") }?;
        Ok(tree.file.verify()?)
    })
}

/// Fills `*out` with what the tree's header says (constant time).
///
/// # Safety
///
/// `tree` is NULL or an open tree; `out` is NULL or points at a writable `ObbtreeInfo`.
#[no_mangle]
pub unsafe extern "C" fn obbtree_info(
    tree: *const ObbtreeTree,
    out: *mut ObbtreeInfo,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or an open tree (the caller's contract).
        let tree = unsafe { deref(tree, "tree") }?;
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        let info = tree.file.info();
        let (volume, volume_name) = volume(info.bv);
        let (precision, precision_name) = precision(info.precision);
        out.write(ObbtreeInfo {
            version_major: info.version.0,
            version_minor: info.version.1,
            volume,
            precision,
            volume_name: volume_name.as_ptr(),
            precision_name: precision_name.as_ptr(),
            fit_name: fit_name(info.fit).as_ptr(),
            encoding_name: encoding_name(info.encoding).as_ptr(),
            triangles: info.triangles,
            vertices: info.vertices,
            nodes: info.nodes,
            leaves: info.stats.shape.leaves,
            depth: info.stats.shape.depth,
            max_leaf_faces: info.stats.shape.max_leaf_faces,
            leaf_size: info.leaf_size,
            degenerate_triangles: info.stats.degenerate_triangles,
            bounds_min: info.stats.bounds_min,
            bounds_max: info.stats.bounds_max,
            placement_scale: info.placement.scale,
            placement_offset: info.placement.offset,
            file_bytes: info.file_bytes,
            layout_name: layout_name(info.layout).as_ptr(),
        });
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Poses
// ---------------------------------------------------------------------------------------

/// Checks that the 12 numbers at `pose` are a rigid motion as every query requires:
/// `OBBTREE_STATUS_OK`, or `OBBTREE_STATUS_POSE` saying what is wrong. (A rotation within
/// the tolerance passes, and queries use its nearest rotation.)
///
/// # Safety
///
/// `pose` is NULL or points at 12 readable doubles.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pose_check(pose: *const f64) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or 12 doubles (the caller's contract).
        unsafe { read_pose(pose, "pose") }.map(|_| ())
    })
}

/// Writes to `out` the rigid pose nearest to the 12 numbers at `pose` (the rotation
/// replaced by the nearest rotation, as the CLI's `--orthonormalize`): for rotations
/// printed with few decimals. Refuses (`OBBTREE_STATUS_POSE`) a change of any entry by more
/// than 1e-2 (a scaled or sheared matrix), reflections and non-finite numbers. `out` may be
/// `pose` itself.
///
/// # Safety
///
/// `pose` is NULL or points at 12 readable doubles; `out` is NULL or points at 12 writable
/// doubles.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pose_orthonormalize(
    pose: *const f64,
    out: *mut f64,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or 12 readable doubles (the caller's contract). Copied out before
        // `out`, which may be the same memory, is written.
        let values: [f64; 12] = unsafe { slice(pose, 12, "pose") }?
            .try_into()
            .map_err(|_| Error::bad("pose must have 12 numbers"))?;
        check_ptr(out, "out")?;
        let parsed = PoseFormat::RotationTranslation
            .parse(&values, true)
            .map_err(|e| Error::pose("pose", e))?;
        // SAFETY: non-NULL (checked) and 12 writable doubles (the caller's contract); no
        // reference to the input is alive any more.
        let out = unsafe { slots(out, 12, "out") }?;
        for (slot, value) in out.iter_mut().zip(parsed.pose.row_major()) {
            slot.write(value);
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Pair handles: one pose pair per call
// ---------------------------------------------------------------------------------------

/// Makes a pair handle for trees `a` and `b` (they may be the same tree): checks that they
/// store the same volume type, precision and layout (`OBBTREE_STATUS_MISMATCHED_TREES` otherwise)
/// and prepares the traversal once. `*out` is the handle, to be released with
/// `obbtree_pair_free`; NULL on failure. The handle keeps both trees mapped until it is
/// freed, even if they are closed first.
///
/// # Safety
///
/// `a` and `b` are NULL or open trees; `out` is NULL or points at writable storage for one
/// pointer.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_new(
    a: *const ObbtreeTree,
    b: *const ObbtreeTree,
    out: *mut *mut ObbtreePair,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        out.write(std::ptr::null_mut());
        // SAFETY: NULL or open trees (the caller's contract).
        let (a, b) = unsafe { (deref(a, "a")?, deref(b, "b")?) };
        let (a, b) = (Arc::clone(&a.file), Arc::clone(&b.file));
        // SAFETY: the files live in the Arcs' heap allocations, which never move and are
        // freed only when the last Arc goes. The handle holds one Arc of each and drops the
        // query (its `state` field, declared first) before them, so these references never
        // outlive the files; they are never handed out beyond the handle.
        let (fa, fb): (&'static ObbtFile, &'static ObbtFile) =
            unsafe { (&*Arc::as_ptr(&a), &*Arc::as_ptr(&b)) };
        let query = PairQuery::new(fa, fb)?;
        let pair = Box::new(ObbtreePair {
            state: Mutex::new(PairState {
                query,
                collide: CollideResult::default(),
            }),
            _a: a,
            _b: b,
        });
        out.write(Box::into_raw(pair));
        Ok(())
    })
}

/// Releases a pair handle (and, if its trees were closed, their maps). NULL is ignored.
///
/// # Safety
///
/// `pair` is NULL or a handle from `obbtree_pair_new` not yet freed; no other thread is
/// using it, and it is not used after this call.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_free(pair: *mut ObbtreePair) {
    if pair.is_null() {
        return;
    }
    // SAFETY: the pointer came from Box::into_raw in `obbtree_pair_new` and is given back
    // once (the caller's contract).
    let pair = unsafe { Box::from_raw(pair) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(pair)));
}

/// Runs `body` on the handle's state, refusing a handle in use by another thread.
///
/// # Safety
///
/// `pair` is NULL or a live handle.
unsafe fn with_pair<T>(
    pair: *const ObbtreePair,
    body: impl FnOnce(&mut PairState) -> Result<T, Error>,
) -> Result<T, Error> {
    // SAFETY: NULL or a live handle (the caller's contract); only shared access is taken,
    // the mutex gives the exclusive one.
    let pair = unsafe { deref(pair, "pair") }?;
    let mut state = match pair.state.try_lock() {
        Ok(state) => state,
        Err(TryLockError::WouldBlock) => {
            return Err(Error::new(
                ObbtreeStatus::Busy,
                "this pair handle is in use by another thread; give each thread its own",
            ))
        }
        Err(TryLockError::Poisoned(_)) => {
            return Err(Error::new(
                ObbtreeStatus::InternalError,
                "this pair handle was left unusable by an earlier internal error; free it and make a new one",
            ))
        }
    };
    body(&mut state)
}

/// Writes the first `capacity` of `pairs` at `buffer` and refuses a short buffer after
/// writing them. A NULL buffer with capacity 0 asks for the count only.
///
/// # Safety
///
/// `buffer` is NULL or points at `capacity` writable pairs.
unsafe fn write_pairs(
    pairs: impl ExactSizeIterator<Item = (u32, u32)>,
    buffer: *mut ObbtreeTrianglePair,
    capacity: usize,
) -> Result<(), Error> {
    let needed = pairs.len();
    if buffer.is_null() && capacity == 0 {
        return Ok(());
    }
    // SAFETY: NULL or `capacity` writable pairs (the caller's contract).
    let slots = unsafe { slots(buffer, capacity, "pairs") }?;
    for (slot, (tri_a, tri_b)) in slots.iter_mut().zip(pairs) {
        slot.write(ObbtreeTrianglePair { tri_a, tri_b });
    }
    if needed > capacity {
        return Err(Error::new(
            ObbtreeStatus::BufferTooSmall,
            format!("the pairs buffer holds {capacity} pairs but {needed} are needed"),
        ));
    }
    Ok(())
}

/// Refuses a NULL buffer with a nonzero capacity before any work is done.
fn check_pairs_buffer(buffer: *const ObbtreeTrianglePair, capacity: usize) -> Result<(), Error> {
    if buffer.is_null() && capacity == 0 {
        return Ok(());
    }
    check_ptr(buffer, "pairs")?;
    check_len::<ObbtreeTrianglePair>(capacity, "pairs")
}

/// Collision between A at `pose_a` and B at `pose_b`: every contacting triangle pair,
/// sorted by (A, B) id, or with `first_contact` the first one found (stops there: the
/// cheapest yes/no answer).
///
/// `*out` gets the answer; the pairs go to `pairs`, which holds `capacity` of them. Pass
/// NULL and 0 for the count only. When `pairs` is too short the call returns
/// `OBBTREE_STATUS_BUFFER_TOO_SMALL` with `*out` complete (`out->pair_count` is the size
/// needed) and the first `capacity` pairs written.
///
/// # Safety
///
/// `pair` is NULL or a live handle; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `pairs` is NULL or points at `capacity` writable pairs; `out` is NULL or points
/// at a writable result. Output buffers do not overlap the inputs.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_collide(
    pair: *mut ObbtreePair,
    pose_a: *const f64,
    pose_b: *const f64,
    first_contact: bool,
    pairs: *mut ObbtreeTrianglePair,
    capacity: usize,
    out: *mut ObbtreeCollideResult,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        check_pairs_buffer(pairs, capacity)?;
        // SAFETY: NULL or 12 doubles each (the caller's contract).
        let (pa, pb) = unsafe { (read_pose(pose_a, "pose_a")?, read_pose(pose_b, "pose_b")?) };
        let options = CollideOptions {
            first_contact,
            ..CollideOptions::default()
        };
        let query = |state: &mut PairState| {
            let PairState { query, collide } = state;
            query.collide_into(&pa, &pb, &options, collide)?;
            out.write(ObbtreeCollideResult {
                colliding: collide.colliding,
                pair_count: collide.pairs.len(),
                pair_offset: 0,
                work: work(&collide.work),
            });
            // SAFETY: NULL or `capacity` writable pairs (the caller's contract).
            unsafe { write_pairs(collide.pairs.iter().copied(), pairs, capacity) }
        };
        // SAFETY: NULL or a live handle (the caller's contract).
        unsafe { with_pair(pair, query) }
    })
}

/// The options of a distance query (the library refuses values out of range, with the
/// CLI's message).
fn distance_options(rel_err: f64, abs_err: f64, max_distance: f64) -> DistanceOptions {
    DistanceOptions {
        rel_err,
        abs_err,
        max_distance,
        ..DistanceOptions::default()
    }
}

/// The separation distance between A at `pose_a` and B at `pose_b`, with the closest
/// points and triangles. Exact with both errors 0; otherwise the distance `d` returned and
/// the true one `d*` satisfy `d* <= d <= max(d* (1 + rel_err), d* + abs_err)`. With a
/// finite `max_distance` (world units; pass `INFINITY` for none), models at least that far
/// apart give `found = 0` and distance +infinity, and pairs of volumes that far apart are
/// never opened. `OBBTREE_STATUS_BAD_ARGUMENT` for a negative or non-finite error, or a
/// `max_distance` that is not greater than 0.
///
/// # Safety
///
/// `pair` is NULL or a live handle; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `out` is NULL or points at a writable result.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_distance(
    pair: *mut ObbtreePair,
    pose_a: *const f64,
    pose_b: *const f64,
    rel_err: f64,
    abs_err: f64,
    max_distance: f64,
    out: *mut ObbtreeDistanceResult,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        // SAFETY: NULL or 12 doubles each (the caller's contract).
        let (pa, pb) = unsafe { (read_pose(pose_a, "pose_a")?, read_pose(pose_b, "pose_b")?) };
        let options = distance_options(rel_err, abs_err, max_distance);
        // SAFETY: NULL or a live handle (the caller's contract).
        let result = unsafe { with_pair(pair, |s| Ok(s.query.distance(&pa, &pb, &options)?)) }?;
        out.write(ObbtreeDistanceResult::from(&result));
        Ok(())
    })
}

/// Whether A at `pose_a` and B at `pose_b` come closer than `tolerance` (world units, at
/// least 0), stopping as soon as that is known; with `closer`, a pair closer than the
/// tolerance. `OBBTREE_STATUS_BAD_ARGUMENT` for a negative or non-finite tolerance.
///
/// # Safety
///
/// `pair` is NULL or a live handle; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `out` is NULL or points at a writable result.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_within(
    pair: *mut ObbtreePair,
    pose_a: *const f64,
    pose_b: *const f64,
    tolerance: f64,
    out: *mut ObbtreeToleranceResult,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        // SAFETY: NULL or 12 doubles each (the caller's contract).
        let (pa, pb) = unsafe { (read_pose(pose_a, "pose_a")?, read_pose(pose_b, "pose_b")?) };
        let options = ToleranceOptions::new(tolerance);
        // SAFETY: NULL or a live handle (the caller's contract).
        let result = unsafe { with_pair(pair, |s| Ok(s.query.within(&pa, &pb, &options)?)) }?;
        out.write(ObbtreeToleranceResult::from(&result));
        Ok(())
    })
}

/// The span of A at `pose_a` and B at `pose_b`: the largest distance between a point of A
/// and a point of B, with the pair realising it.
///
/// # Safety
///
/// `pair` is NULL or a live handle; `pose_a`, `pose_b` are NULL or point at 12 readable
/// doubles; `out` is NULL or points at a writable result.
#[no_mangle]
pub unsafe extern "C" fn obbtree_pair_span(
    pair: *mut ObbtreePair,
    pose_a: *const f64,
    pose_b: *const f64,
    out: *mut ObbtreeSpanResult,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or writable (the caller's contract).
        let out = unsafe { slot(out, "out") }?;
        // SAFETY: NULL or 12 doubles each (the caller's contract).
        let (pa, pb) = unsafe { (read_pose(pose_a, "pose_a")?, read_pose(pose_b, "pose_b")?) };
        let options = SpanOptions::default();
        // SAFETY: NULL or a live handle (the caller's contract).
        let result = unsafe { with_pair(pair, |s| Ok(s.query.span(&pa, &pb, &options)?)) }?;
        out.write(ObbtreeSpanResult::from(&result));
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Batches: many pose pairs per call, in parallel
// ---------------------------------------------------------------------------------------

/// The trees and poses of a batch call, checked.
struct Batch<'a> {
    a: &'a ObbtFile,
    b: &'a ObbtFile,
    poses_a: Vec<Pose>,
    poses_b: Vec<Pose>,
    options: BatchOptions,
}

/// A `threads` argument checked: 0 is `None` (the global pool, one thread per core).
fn thread_count(threads: usize) -> Result<Option<NonZeroUsize>, Error> {
    if threads > OBBTREE_MAX_THREADS {
        return Err(Error::bad(format!(
            "threads is {threads}: at most {OBBTREE_MAX_THREADS} (0 for one per core)"
        )));
    }
    Ok(NonZeroUsize::new(threads))
}

/// The poses of one side of a batch, each checked; the first bad one is named.
fn read_poses(values: &[f64], name: &str) -> Result<Vec<Pose>, Error> {
    let poses: Vec<Result<Pose, PoseError>> = values
        .par_chunks_exact(12)
        .map(Pose::from_row_major)
        .collect();
    poses
        .into_iter()
        .enumerate()
        .map(|(i, pose)| pose.map_err(|e| Error::pose(&format!("{name}[{i}]"), e)))
        .collect()
}

impl<'a> Batch<'a> {
    /// Checks the arguments every batch call shares.
    ///
    /// # Safety
    ///
    /// `a`, `b` are NULL or open trees; `poses_a` (`poses_b`) is NULL or points at
    /// `12 * count_a` (`12 * count_b`) readable doubles.
    #[allow(clippy::too_many_arguments)]
    unsafe fn new(
        a: *const ObbtreeTree,
        poses_a: *const f64,
        count_a: usize,
        b: *const ObbtreeTree,
        poses_b: *const f64,
        count_b: usize,
        threads: usize,
        results_len: usize,
    ) -> Result<Batch<'a>, Error> {
        // SAFETY: NULL or open trees (the caller's contract).
        let (a, b) = unsafe { (deref(a, "a")?, deref(b, "b")?) };
        let threads = thread_count(threads)?;
        let numbers = |count: usize, name: &str| {
            count
                .checked_mul(12)
                .ok_or_else(|| Error::bad(format!("{name}: count {count} is too large")))
        };
        let (len_a, len_b) = (numbers(count_a, "poses_a")?, numbers(count_b, "poses_b")?);
        // SAFETY: NULL or 12 * count doubles each (the caller's contract).
        let (values_a, values_b) = unsafe {
            (
                slice(poses_a, len_a, "poses_a")?,
                slice(poses_b, len_b, "poses_b")?,
            )
        };
        let batch = Batch {
            a: &a.file,
            b: &b.file,
            poses_a: read_poses(values_a, "poses_a")?,
            poses_b: read_poses(values_b, "poses_b")?,
            options: BatchOptions { threads },
        };
        let n = batch.poses()?.len();
        if results_len != n {
            return Err(Error::bad(format!(
                "results_len is {results_len} but the batch has {n} queries"
            )));
        }
        Ok(batch)
    }

    fn poses(&self) -> Result<PoseBatch<'_>, Error> {
        PoseBatch::new(&self.poses_a, &self.poses_b).map_err(|e| match e {
            BatchError::Lengths { a, b } => Error::bad(format!(
                "count_a is {a} and count_b is {b}: they must be equal, or one of them 1 (a pose used with every pose of the other side)"
            )),
            other => Error::from(other),
        })
    }

    /// Runs `query` on every pose pair, in parallel, and returns the answers in pose
    /// order, or the error of the first pose that failed.
    fn run<T: Send>(
        &self,
        query: impl Fn(&mut PairQuery<'_>, &Pose, &Pose) -> Result<T, QueryError> + Sync,
    ) -> Result<Vec<T>, Error> {
        batch(self.a, self.b, self.poses()?, &self.options, query)?
            .into_iter()
            .enumerate()
            .map(|(i, answer)| {
                answer.map_err(|e| {
                    // An option out of range is the same for every pose: not named by one.
                    let named = !matches!(e, QueryError::BadOption { .. });
                    let e = Error::from(e);
                    if named {
                        Error::new(e.status, format!("pose {i}: {}", e.message))
                    } else {
                        e
                    }
                })
            })
            .collect()
    }
}

/// Collision for a batch of poses, in parallel: query `i` places A at pose `i` of
/// `poses_a` and B at pose `i` of `poses_b` (12 doubles each, one after the other). The
/// counts are equal, or one is 1 and that pose is used for every query (broadcast); the
/// batch has `max(count_a, count_b)` queries and `results` holds `results_len` answers,
/// which must equal it. `threads` 0 uses rayon's global pool (one thread per core, or
/// `RAYON_NUM_THREADS`), otherwise a pool of that many threads (at most
/// `OBBTREE_MAX_THREADS`) made for the call.
///
/// The pairs of every query go to `pairs` one after the other in pose order
/// (`results[i].pair_offset` is where query `i`'s begin); `*pairs_total` (if not NULL)
/// gets the number of them all. Pass NULL and 0 for counts only. When `pairs` is too short
/// the call returns `OBBTREE_STATUS_BUFFER_TOO_SMALL` with every result complete and the
/// first `capacity` pairs written.
///
/// Errors name the pose: `OBBTREE_STATUS_POSE` for a bad pose (checked before any query),
/// the first failing query's error otherwise.
///
/// # Safety
///
/// `a`, `b` are NULL or open trees; `poses_a` (`poses_b`) is NULL or points at
/// `12 * count_a` (`12 * count_b`) readable doubles; `results` is NULL or points at
/// `results_len` writable results; `pairs` is NULL or points at `capacity` writable
/// pairs; `pairs_total` is NULL or writable. Output buffers do not overlap each other or
/// the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_collide_batch(
    a: *const ObbtreeTree,
    poses_a: *const f64,
    count_a: usize,
    b: *const ObbtreeTree,
    poses_b: *const f64,
    count_b: usize,
    first_contact: bool,
    threads: usize,
    results: *mut ObbtreeCollideResult,
    results_len: usize,
    pairs: *mut ObbtreeTrianglePair,
    capacity: usize,
    pairs_total: *mut usize,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or `results_len` writable results (the caller's contract).
        let results = unsafe { slots(results, results_len, "results") }?;
        check_pairs_buffer(pairs, capacity)?;
        let total_slot = if pairs_total.is_null() {
            None
        } else {
            // SAFETY: non-NULL, so writable (the caller's contract).
            Some(unsafe { slot(pairs_total, "pairs_total") }?)
        };
        // SAFETY: forwarded from the caller's contract.
        let batch = unsafe {
            Batch::new(
                a,
                poses_a,
                count_a,
                b,
                poses_b,
                count_b,
                threads,
                results_len,
            )
        }?;
        let options = CollideOptions {
            first_contact,
            ..CollideOptions::default()
        };
        let answers = batch.run(|pair, pa, pb| pair.collide(pa, pb, &options))?;
        let mut offset = 0;
        for (slot, answer) in results.iter_mut().zip(&answers) {
            slot.write(ObbtreeCollideResult {
                colliding: answer.colliding,
                pair_count: answer.pairs.len(),
                pair_offset: offset,
                work: work(&answer.work),
            });
            offset += answer.pairs.len();
        }
        if let Some(total) = total_slot {
            total.write(offset);
        }
        let all = answers.iter().flat_map(|a| a.pairs.iter().copied());
        // SAFETY: NULL or `capacity` writable pairs (the caller's contract).
        unsafe { write_pairs(Counted(all, offset), pairs, capacity) }
    })
}

/// An iterator with a length known beforehand (the pairs of a batch, counted while
/// writing the results).
struct Counted<I>(I, usize);

impl<I: Iterator> Iterator for Counted<I> {
    type Item = I::Item;
    fn next(&mut self) -> Option<I::Item> {
        let item = self.0.next()?;
        self.1 = self.1.saturating_sub(1);
        Some(item)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.1, Some(self.1))
    }
}

impl<I: Iterator> ExactSizeIterator for Counted<I> {}

/// `obbtree_pair_distance` for a batch of poses, in parallel; the poses, counts,
/// `threads` and `results_len` as for `obbtree_collide_batch`.
///
/// # Safety
///
/// `a`, `b` are NULL or open trees; `poses_a` (`poses_b`) is NULL or points at
/// `12 * count_a` (`12 * count_b`) readable doubles; `results` is NULL or points at
/// `results_len` writable results, not overlapping the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_distance_batch(
    a: *const ObbtreeTree,
    poses_a: *const f64,
    count_a: usize,
    b: *const ObbtreeTree,
    poses_b: *const f64,
    count_b: usize,
    rel_err: f64,
    abs_err: f64,
    max_distance: f64,
    threads: usize,
    results: *mut ObbtreeDistanceResult,
    results_len: usize,
) -> ObbtreeStatus {
    let options = distance_options(rel_err, abs_err, max_distance);
    // SAFETY: forwarded from the caller's contract.
    unsafe {
        one_record_per_pose(
            (a, poses_a, count_a),
            (b, poses_b, count_b),
            threads,
            (results, results_len),
            |pair, pa, pb| pair.distance(pa, pb, &options),
            |answer| ObbtreeDistanceResult::from(answer),
        )
    }
}

/// `obbtree_pair_within` for a batch of poses, in parallel; the poses, counts, `threads`
/// and `results_len` as for `obbtree_collide_batch`.
///
/// # Safety
///
/// `a`, `b` are NULL or open trees; `poses_a` (`poses_b`) is NULL or points at
/// `12 * count_a` (`12 * count_b`) readable doubles; `results` is NULL or points at
/// `results_len` writable results, not overlapping the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_within_batch(
    a: *const ObbtreeTree,
    poses_a: *const f64,
    count_a: usize,
    b: *const ObbtreeTree,
    poses_b: *const f64,
    count_b: usize,
    tolerance: f64,
    threads: usize,
    results: *mut ObbtreeToleranceResult,
    results_len: usize,
) -> ObbtreeStatus {
    // SAFETY: forwarded from the caller's contract.
    unsafe {
        one_record_per_pose(
            (a, poses_a, count_a),
            (b, poses_b, count_b),
            threads,
            (results, results_len),
            |pair, pa, pb| pair.within(pa, pb, &ToleranceOptions::new(tolerance)),
            |answer| ObbtreeToleranceResult::from(answer),
        )
    }
}

/// `obbtree_pair_span` for a batch of poses, in parallel; the poses, counts, `threads`
/// and `results_len` as for `obbtree_collide_batch`.
///
/// # Safety
///
/// `a`, `b` are NULL or open trees; `poses_a` (`poses_b`) is NULL or points at
/// `12 * count_a` (`12 * count_b`) readable doubles; `results` is NULL or points at
/// `results_len` writable results, not overlapping the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_span_batch(
    a: *const ObbtreeTree,
    poses_a: *const f64,
    count_a: usize,
    b: *const ObbtreeTree,
    poses_b: *const f64,
    count_b: usize,
    threads: usize,
    results: *mut ObbtreeSpanResult,
    results_len: usize,
) -> ObbtreeStatus {
    // SAFETY: forwarded from the caller's contract.
    unsafe {
        one_record_per_pose(
            (a, poses_a, count_a),
            (b, poses_b, count_b),
            threads,
            (results, results_len),
            |pair, pa, pb| pair.span(pa, pb, &SpanOptions::default()),
            |answer| ObbtreeSpanResult::from(answer),
        )
    }
}

/// The batched queries whose answer is one record per pose (distance, within, span): the
/// output checked, the batch read, `query` run on every pose pair in parallel, and each
/// answer written through `record`.
///
/// # Safety
///
/// As the batch entry points: the trees NULL or open, each pose pointer NULL or pointing
/// at 12 readable doubles per pose, `results` NULL or pointing at `results_len` writable
/// records not overlapping the inputs.
unsafe fn one_record_per_pose<A: Send, R>(
    (a, poses_a, count_a): (*const ObbtreeTree, *const f64, usize),
    (b, poses_b, count_b): (*const ObbtreeTree, *const f64, usize),
    threads: usize,
    (results, results_len): (*mut R, usize),
    query: impl Fn(&mut PairQuery<'_>, &Pose, &Pose) -> Result<A, QueryError> + Sync,
    record: impl Fn(&A) -> R,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: NULL or `results_len` writable results (the caller's contract).
        let results = unsafe { slots(results, results_len, "results") }?;
        // SAFETY: forwarded from the caller's contract.
        let batch = unsafe {
            Batch::new(
                a,
                poses_a,
                count_a,
                b,
                poses_b,
                count_b,
                threads,
                results_len,
            )
        }?;
        let answers = batch.run(query)?;
        for (slot, answer) in results.iter_mut().zip(&answers) {
            slot.write(record(answer));
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        // SAFETY: obbtree_last_error never returns NULL and the string is NUL-terminated.
        unsafe { CStr::from_ptr(obbtree_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn a_panic_becomes_an_internal_error_with_its_message() {
        let status = guard(|| panic!("boom at the boundary"));
        assert_eq!(status, ObbtreeStatus::InternalError);
        let message = last_error();
        assert!(message.contains("boom at the boundary"), "{message}");
        assert!(message.contains("internal error"), "{message}");
        // A later success clears the message.
        assert_eq!(guard(|| Ok(())), ObbtreeStatus::Ok);
        assert_eq!(last_error(), "");
    }

    #[test]
    fn messages_with_nul_bytes_survive() {
        let status = guard(|| Err(Error::bad("a\0b")));
        assert_eq!(status, ObbtreeStatus::BadArgument);
        assert_eq!(last_error(), "a\\0b");
    }

    /// A pair handle of the cow's tree with itself (built in memory).
    fn cow_pair() -> *mut ObbtreePair {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/cow.obj");
        let mesh = obbtree::mesh::TriMesh::load(root.as_ref()).expect("cow loads");
        let file = obbtree::build::build(&mesh, &Default::default(), None).expect("builds");
        let tree = ObbtreeTree {
            file: Arc::new(file),
        };
        let mut pair = std::ptr::null_mut();
        // SAFETY: a live tree and a writable pointer; the handle keeps the file alive
        // after `tree` is dropped.
        let status = unsafe { obbtree_pair_new(&tree, &tree, &mut pair) };
        assert_eq!(status, ObbtreeStatus::Ok);
        pair
    }

    fn span(pair: *mut ObbtreePair) -> ObbtreeStatus {
        let pose = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let mut out = MaybeUninit::<ObbtreeSpanResult>::uninit();
        // SAFETY: a live handle, 12 doubles each, a writable result.
        unsafe { obbtree_pair_span(pair, pose.as_ptr(), pose.as_ptr(), out.as_mut_ptr()) }
    }

    #[test]
    fn a_handle_in_use_is_busy_and_a_poisoned_one_refuses() {
        let pair = cow_pair();
        // SAFETY: the handle is live until freed below.
        let handle = unsafe { &*pair };
        {
            // Another thread inside a call holds the lock: this call must not wait or race.
            let _inside = handle.state.lock().expect("not poisoned");
            assert_eq!(span(pair), ObbtreeStatus::Busy);
            assert!(last_error().contains("in use by another thread"));
        }
        assert_eq!(span(pair), ObbtreeStatus::Ok);
        // A panic while the lock was held (a bug) leaves the handle refusing, not broken.
        let _ = catch_unwind(AssertUnwindSafe(|| {
            let _inside = handle.state.lock();
            panic!("poison");
        }));
        assert_eq!(span(pair), ObbtreeStatus::InternalError);
        assert!(last_error().contains("free it and make a new one"));
        // SAFETY: made above, freed once.
        unsafe { obbtree_pair_free(pair) };
    }

    #[test]
    fn status_names_match_the_enum() {
        for (status, name) in [
            (ObbtreeStatus::Ok, "OBBTREE_STATUS_OK"),
            (
                ObbtreeStatus::BufferTooSmall,
                "OBBTREE_STATUS_BUFFER_TOO_SMALL",
            ),
            (
                ObbtreeStatus::InternalError,
                "OBBTREE_STATUS_INTERNAL_ERROR",
            ),
        ] {
            // SAFETY: a static NUL-terminated string.
            let got = unsafe { CStr::from_ptr(obbtree_status_name(status as i32)) };
            assert_eq!(got.to_str().ok(), Some(name));
        }
        // SAFETY: as above.
        let unknown = unsafe { CStr::from_ptr(obbtree_status_name(99)) };
        assert_eq!(unknown.to_str().ok(), Some("unknown"));
    }
}
