//! Batches of query points answered in an order that follows space: the descents of nearby
//! points read the same nodes, so taking them one after another keeps those nodes in cache,
//! where points in the caller's order (a random cloud, a grid row by row) each fetch most
//! of their path from memory again.

use rayon::prelude::*;

/// Bits per coordinate of the grid the order is taken on: 2²¹ cells a side, far finer
/// than any batch needs, and three of them fit one 64-bit code.
const BITS: u32 = 21;

/// `f` of every point, computed in parallel in Morton order of a grid over the points'
/// bounding box, returned in the points' order. `init` makes each worker's scratch. The
/// first error in Morton order is returned.
pub(super) fn map_in_space_order<T, E, S>(
    points: &[[f64; 3]],
    init: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut S, &[f64; 3]) -> Result<T, E> + Sync + Send,
) -> Result<Vec<T>, E>
where
    T: Send,
    E: Send,
{
    let mut order: Vec<(u64, usize)> = codes(points).into_iter().zip(0..).collect();
    order.par_sort_unstable();
    let answers: Vec<(usize, T)> = order
        .par_iter()
        .map_init(init, |scratch, &(_, i)| {
            let p = points.get(i).copied().unwrap_or_default();
            f(scratch, &p).map(|answer| (i, answer))
        })
        .collect::<Result<_, E>>()?;
    let mut out: Vec<Option<T>> = std::iter::repeat_with(|| None).take(points.len()).collect();
    for (i, answer) in answers {
        if let Some(slot) = out.get_mut(i) {
            *slot = Some(answer);
        }
    }
    Ok(out.into_iter().flatten().collect())
}

/// Each point's Morton code on a grid of 2^[`BITS`] cells a side over the points' box.
fn codes(points: &[[f64; 3]]) -> Vec<u64> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for ((lo, hi), x) in lo.iter_mut().zip(hi.iter_mut()).zip(p) {
            *lo = lo.min(*x);
            *hi = hi.max(*x);
        }
    }
    let cells = f64::from((1u32 << BITS) - 1);
    // (A zero extent makes the scale infinite and every offset 0 × ∞ = NaN, which the
    // cast below saturates to cell 0, as it should.)
    let scale = std::array::from_fn::<f64, 3, _>(|k| {
        cells / hi.get(k).zip(lo.get(k)).map_or(0.0, |(h, l)| h - l)
    });
    points
        .iter()
        .map(|p| {
            let cell = |k: usize| {
                let offset = p.get(k).zip(lo.get(k)).map_or(0.0, |(x, l)| x - l);
                // (Saturating: a NaN or overflow lands in a corner cell, still answered.)
                (offset * scale.get(k).copied().unwrap_or(0.0)) as u32
            };
            spread(cell(0)) | spread(cell(1)) << 1 | spread(cell(2)) << 2
        })
        .collect()
}

/// The low [`BITS`] bits of `v` moved to every third bit.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & ((1 << BITS) - 1);
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_puts_each_bit_three_apart() {
        for bit in 0..BITS {
            assert_eq!(spread(1 << bit), 1u64 << (3 * bit));
        }
        assert_eq!(spread(u32::MAX), 0x1249_2492_4924_9249);
    }

    /// Answers come back in the points' order, whatever order they were computed in,
    /// and nearby points are computed one after another.
    #[test]
    fn answers_come_back_in_the_points_order() {
        let mut rng = crate::generate::Rng::new(5);
        let points: Vec<[f64; 3]> = (0..1000)
            .map(|_| [rng.signed(), rng.signed(), rng.signed()])
            .collect();
        let out = map_in_space_order(&points, || (), |_, p| Ok::<_, ()>(*p)).expect("answers");
        assert_eq!(out, points);
        // Consecutive points are near: a third of the mean step of the caller's order.
        let mut order: Vec<(u64, usize)> = codes(&points).into_iter().zip(0..).collect();
        order.sort_unstable();
        let step =
            |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        let mean = |path: &[usize]| {
            path.windows(2)
                .map(|w| step(&points[w[0]], &points[w[1]]))
                .sum::<f64>()
                / 999.0
        };
        let given: Vec<usize> = (0..points.len()).collect();
        let spatial: Vec<usize> = order.iter().map(|&(_, i)| i).collect();
        assert!(
            mean(&spatial) < mean(&given) / 3.0,
            "{} {}",
            mean(&spatial),
            mean(&given)
        );
        // An error is returned as such.
        let failed = map_in_space_order(
            &points,
            || (),
            |_, p| if p[1] > 0.9 { Err(p[1]) } else { Ok(()) },
        );
        assert!(failed.is_err());
    }
}
