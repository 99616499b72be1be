//! Many poses of one pair of models answered in one call, in parallel: what the CLI's pose
//! files and the Python and C batch calls all run.

use std::cell::RefCell;
use std::num::NonZeroUsize;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::{PairQuery, Pose, QueryContext, QueryError};
use crate::format::ObbtFile;

/// The poses of a batch: query `i` places A at `a[i]` and B at `b[i]`. A side that holds
/// one pose holds it for every query (it broadcasts), so the batch has as many queries as
/// the longer side.
///
/// # Examples
///
/// ```
/// use obbtree::query::{Pose, PoseBatch};
///
/// let fixed = [Pose::identity()];
/// let moving: Vec<Pose> = (0..5).map(|i| Pose::translation(f64::from(i), 0.0, 0.0)).collect();
/// let batch = PoseBatch::new(&fixed, &moving)?;
/// assert_eq!(batch.len(), 5);
/// assert!(PoseBatch::new(&moving[..2], &moving[..3]).is_err());
/// # Ok::<(), obbtree::query::BatchError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct PoseBatch<'p> {
    a: &'p [Pose],
    b: &'p [Pose],
    len: usize,
}

impl<'p> PoseBatch<'p> {
    /// A's poses and B's poses, paired by index.
    ///
    /// # Errors
    ///
    /// [`BatchError::Lengths`] when the sides hold different numbers of poses and neither
    /// holds exactly one.
    pub fn new(a: &'p [Pose], b: &'p [Pose]) -> Result<PoseBatch<'p>, BatchError> {
        let len = match (a.len(), b.len()) {
            (x, y) if x == y => x,
            (1, y) => y,
            (x, 1) => x,
            (x, y) => return Err(BatchError::Lengths { a: x, b: y }),
        };
        Ok(PoseBatch { a, b, len })
    }

    /// The number of queries.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the batch has no query.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The poses of each query in order (A's, B's).
    pub fn iter(&self) -> impl Iterator<Item = (&'p Pose, &'p Pose)> + 'p {
        // Cycling a side of `len` poses gives them once; cycling a side of one repeats it.
        self.a
            .iter()
            .cycle()
            .zip(self.b.iter().cycle())
            .take(self.len)
    }
}

/// How a batch runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BatchOptions {
    /// Worker threads. `None` runs on the rayon pool the call is made in (the global one:
    /// one thread per core, unless the caller installed another); `Some(n)` on a pool of
    /// `n` threads, made on first use and kept for later batches of the same count
    /// (making a pool costs more than a small batch).
    pub threads: Option<NonZeroUsize>,
}

/// Why a batch could not run. A query that fails for one pose is not a `BatchError`: it is
/// that pose's answer (see [`batch`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BatchError {
    /// The two sides hold different numbers of poses and neither holds one.
    #[error("A has {a} poses and B has {b}: give batches of one length, or one pose to broadcast")]
    Lengths {
        /// A's pose count.
        a: usize,
        /// B's pose count.
        b: usize,
    },
    /// The two trees cannot be queried together (see [`PairQuery::new`]).
    #[error(transparent)]
    Pair(#[from] QueryError),
    /// The worker threads could not be started.
    #[error("could not start {threads} threads")]
    Threads {
        /// The thread count asked for.
        threads: usize,
        /// Why.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
}

/// Runs `query` for every pose pair of `poses`, in parallel, and returns the answers in pose
/// order. Each worker thread makes one [`PairQuery`] of A and B with traversal scratch it
/// keeps between batches, and hands it to `query` with the poses of each query it takes.
///
/// A query's error is its pose's answer: the caller decides whether the first one ends the
/// batch (the bindings) or the answers before it still count (the CLI prints them). A
/// batch of one query, or [`BatchOptions::threads`] of one, runs on the calling thread.
///
/// # Errors
///
/// [`BatchError::Pair`] when A and B cannot be queried together (checked once, before any
/// pose), [`BatchError::Threads`] when a pool of the asked size cannot be made.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{batch, BatchOptions, CollideOptions, Pose, PoseBatch, QueryError};
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let here = [Pose::identity()];
/// let there: Vec<Pose> = (0..100).map(|i| Pose::translation(0.02 * f64::from(i), 0.0, 0.0)).collect();
/// let first = CollideOptions { first_contact: true, ..CollideOptions::default() };
/// let touching = batch(
///     &cow,
///     &cow,
///     PoseBatch::new(&here, &there)?,
///     &BatchOptions::default(),
///     |pair, a, b| pair.collide(a, b, &first).map(|r| r.colliding),
/// )?
/// .into_iter()
/// .collect::<Result<Vec<bool>, QueryError>>()?;
/// assert!(touching[0] && !touching[99]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn batch<T, E, F>(
    a: &ObbtFile,
    b: &ObbtFile,
    poses: PoseBatch<'_>,
    options: &BatchOptions,
    query: F,
) -> Result<Vec<Result<T, E>>, BatchError>
where
    T: Send,
    E: Send + From<QueryError>,
    F: Fn(&mut PairQuery<'_>, &Pose, &Pose) -> Result<T, E> + Sync,
{
    // Checks the pair once, also for an empty batch: every worker can then make its own.
    let mut first = Pooled::new(a, b)?;
    if poses.len() <= 1 || options.threads.map(NonZeroUsize::get) == Some(1) {
        return Ok(poses
            .iter()
            .map(|(pose_a, pose_b)| query(&mut first.0, pose_a, pose_b))
            .collect());
    }
    drop(first);
    let pairs: Vec<(&Pose, &Pose)> = poses.iter().collect();
    let parallel = || -> Vec<Result<T, E>> {
        pairs
            .par_iter()
            .with_min_len(4)
            .map_init(
                || Pooled::new(a, b),
                |pooled, (pose_a, pose_b)| match pooled {
                    Ok(pooled) => query(&mut pooled.0, pose_a, pose_b),
                    Err(e) => Err(E::from(e.clone())),
                },
            )
            .collect()
    };
    on_threads(options.threads, parallel)
}

/// Runs `work` on the rayon pool the call is made in (`threads` `None`) or on a pool of
/// `n` threads, made on first use and kept for later calls of the same count. The
/// one-model queries ([`cast_rays`](super::cast_rays), [`closest_points`](super::closest_points),
/// [`winding_numbers`](super::winding_numbers)) run on the pool they are called in: wrap
/// them in this to choose their thread count, as [`batch`] does with
/// [`BatchOptions::threads`].
///
/// # Errors
///
/// [`BatchError::Threads`] when a pool of that size cannot be made.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{closest_points, on_threads, ClosestOptions, Pose};
/// use std::num::NonZeroUsize;
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let points: Vec<[f64; 3]> = (0..100).map(|i| [0.01 * f64::from(i), 0.5, 0.0]).collect();
/// let one = NonZeroUsize::new(1);
/// let answers = on_threads(one, || {
///     closest_points(&cow, &Pose::identity(), &points, &ClosestOptions::default())
/// })??;
/// assert_eq!(answers.len(), 100);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn on_threads<T: Send>(
    threads: Option<NonZeroUsize>,
    work: impl FnOnce() -> T + Send,
) -> Result<T, BatchError> {
    Ok(match threads {
        None => work(),
        Some(threads) => pool(threads.get())?.install(work),
    })
}

/// Thread pools made for [`on_threads`], kept for later calls.
static POOLS: Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());

fn pool(threads: usize) -> Result<Arc<rayon::ThreadPool>, BatchError> {
    // A panic while the lock was held cannot leave the list half-changed: use it anyway.
    let mut pools = POOLS.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, made)) = pools.iter().find(|(n, _)| *n == threads) {
        return Ok(made.clone());
    }
    let made = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|source| BatchError::Threads { threads, source })?;
    let made = Arc::new(made);
    pools.push((threads, made.clone()));
    Ok(made)
}

thread_local! {
    /// Traversal scratch kept per thread between batches, so that a query's buffers grow
    /// to its traversal's size once per thread, not once per batch.
    static SCRATCH: RefCell<Option<QueryContext>> = const { RefCell::new(None) };
}

/// A [`PairQuery`] made with this thread's kept scratch, which it gives back when dropped.
struct Pooled<'f>(PairQuery<'f>);

impl<'f> Pooled<'f> {
    fn new(a: &'f ObbtFile, b: &'f ObbtFile) -> Result<Pooled<'f>, QueryError> {
        let context = SCRATCH
            .try_with(|s| s.try_borrow_mut().ok().and_then(|mut s| s.take()))
            .ok()
            .flatten()
            .unwrap_or_default();
        Ok(Pooled(PairQuery::with_context(a, b, context)?))
    }
}

impl Drop for Pooled<'_> {
    fn drop(&mut self) {
        let context = self.0.take_context();
        let _ = SCRATCH.try_with(|s| {
            if let Ok(mut s) = s.try_borrow_mut() {
                *s = Some(context);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: usize) -> Pose {
        Pose::translation(x as f64, 0.0, 0.0)
    }

    #[test]
    fn a_batch_pairs_poses_by_index_and_broadcasts_a_single_one() {
        let many: Vec<Pose> = (0..3).map(at).collect();
        let one = [at(7)];
        let x = |p: &Pose| p.translation_vector().x as usize;
        let pairs = |batch: PoseBatch<'_>| -> Vec<(usize, usize)> {
            batch.iter().map(|(a, b)| (x(a), x(b))).collect()
        };
        let both = PoseBatch::new(&many, &many).unwrap();
        assert_eq!((both.len(), both.is_empty()), (3, false));
        assert_eq!(pairs(both), [(0, 0), (1, 1), (2, 2)]);
        let a_fixed = PoseBatch::new(&one, &many).unwrap();
        assert_eq!(a_fixed.len(), 3);
        assert_eq!(pairs(a_fixed), [(7, 0), (7, 1), (7, 2)]);
        let b_fixed = PoseBatch::new(&many, &one).unwrap();
        assert_eq!(pairs(b_fixed), [(0, 7), (1, 7), (2, 7)]);
        let single = PoseBatch::new(&one, &one).unwrap();
        assert_eq!((single.len(), single.is_empty()), (1, false));
        let none = PoseBatch::new(&one, &[]).unwrap();
        assert_eq!((none.len(), none.is_empty()), (0, true));
        assert_eq!(none.iter().count(), 0);
        assert!(matches!(
            PoseBatch::new(&many[..2], &many),
            Err(BatchError::Lengths { a: 2, b: 3 })
        ));
    }

    /// A batch's pair query hands its traversal scratch back to the thread when done, so
    /// that the next batch on that thread starts with buffers already grown.
    #[test]
    fn a_batch_gives_its_scratch_back_to_the_thread() {
        let cube = crate::generate::cuboid([0.5; 3], [0.0; 3]).unwrap();
        let cube = crate::build::build(&cube, &Default::default(), None).unwrap();
        let kept = || SCRATCH.with(|s| s.borrow().as_ref().map(|c| c.stack.capacity()));
        SCRATCH.with(|s| *s.borrow_mut() = None);
        assert_eq!(kept(), None);
        let here = [at(0)];
        let one_thread = BatchOptions {
            threads: NonZeroUsize::new(1),
        };
        let answers = batch(
            &cube,
            &cube,
            PoseBatch::new(&here, &here).unwrap(),
            &one_thread,
            |pair, a, b| pair.collide(a, b, &Default::default()),
        )
        .unwrap();
        assert!(answers[0].as_ref().unwrap().colliding);
        assert!(kept().is_some_and(|capacity| capacity > 0));
    }
}
