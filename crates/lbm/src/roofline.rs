//! Memory-traffic bound of the in-place AA kernel, for benchmarks: one fused read-modify-write
//! pass over all Q direction arrays of a population array in the AA stepper's own (padded)
//! layout, written the way the kernel walks memory (rows spread over the caller's rayon pool with
//! the same `Partition` as the stepper, blocks of two AVX-512 registers across all Q arrays, plain
//! loads and stores, no non-temporal stores), with no arithmetic beyond one multiply per value.
//! With the same partition it also meets the same scheduling: on a shared machine, where another
//! process takes a core now and then, a static split (`Partition::Contiguous`) loses more than
//! work stealing (`Partition::Rows`), for the pass as for the kernel.
//! It moves exactly the AA kernel's bytes per node update (Q reads + Q writes, no write-allocate
//! since every written line was just read) with the least work a kernel can do on them, so a
//! correct stream-collide kernel on the same array cannot run faster: node updates per second
//! of this pass are the bound the benchmark divides the kernel's MLUPS by.

use crate::kernel::SyncPtr;
use crate::layout::Layout;
use crate::real::Real;
use crate::stepper_aa::Partition;
use rayon::prelude::*;

/// Multiply every fluid slot (the `nx` leading slots of each of `rows` rows) of `q` direction arrays
/// in `layout` by `scale`, once. `f` starts at slot 0 of the layout (vector index `layout.base`).
///
/// # Panics
/// If `f` is shorter than `q` direction arrays of the layout.
pub fn in_place_pass<T: Real>(
    f: &mut [T],
    layout: &Layout,
    q: usize,
    rows: usize,
    partition: Partition,
    scale: T,
) {
    in_place_map(f, layout, q, rows, partition, move |v| v * scale);
}

/// [`in_place_pass`] with any value type and any per-value map `op` (the bound of a narrower
/// storage, `storage`: e.g. flipping a bit of each 16-bit value moves its bytes with the least
/// work).
///
/// # Panics
/// If `f` is shorter than `q` direction arrays of the layout.
pub fn in_place_map<T: Copy + Send + Sync, F: Fn(T) -> T + Copy + Send + Sync>(
    f: &mut [T],
    layout: &Layout,
    q: usize,
    rows: usize,
    partition: Partition,
    op: F,
) {
    assert!(
        f.len() >= (q - 1) * layout.stride + rows * layout.nxp,
        "array too short for the layout"
    );
    let ptr = SyncPtr(f.as_mut_ptr());
    let task = |t: usize, per: usize| {
        let p = &ptr;
        for r in t * per..((t + 1) * per).min(rows) {
            // SAFETY: rows of a task belong to it only; indices in bounds (asserted above).
            unsafe { row(p.0.add(r * layout.nxp), layout.stride, layout.nx, q, op) };
        }
    };
    match partition {
        Partition::Rows(k) => {
            let k = k.max(1);
            (0..rows.div_ceil(k)).into_par_iter().for_each(|t| task(t, k));
        }
        Partition::Contiguous => {
            let per = rows.div_ceil(rayon::current_num_threads()).max(1);
            (0..rows.div_ceil(per))
                .into_par_iter()
                .with_max_len(1)
                .for_each(|t| task(t, per));
        }
    }
}

/// One row: blocks of two AVX-512 registers (128 bytes: `kernel::wide` nodes of f32 and f64)
/// across all `q` arrays, then the scalar rest.
///
/// # Safety
/// `p + i * stride + x` must be valid and unshared for i < q, x < nx.
#[inline(always)]
unsafe fn row<T: Copy, F: Fn(T) -> T>(p: *mut T, stride: usize, nx: usize, q: usize, op: F) {
    let wb = 128 / std::mem::size_of::<T>();
    let mut x = 0;
    while x + wb <= nx {
        for i in 0..q {
            // SAFETY: see the function contract.
            let s = unsafe { std::slice::from_raw_parts_mut(p.add(i * stride + x), wb) };
            s.iter_mut().for_each(|v| *v = op(*v));
        }
        x += wb;
    }
    for i in 0..q {
        // SAFETY: see the function contract.
        let s = unsafe { std::slice::from_raw_parts_mut(p.add(i * stride + x), nx - x) };
        s.iter_mut().for_each(|v| *v = op(*v));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pass_scales_every_fluid_slot_once_and_no_padding() {
        let n = [37, 5, 1];
        let mut lay = Layout::padded::<f64>(n);
        let canon: Vec<f64> = (0..9 * 37 * 5).map(|k| k as f64).collect();
        let mut f = lay.pack(&canon, 9);
        let base = lay.base;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for p in [Partition::Rows(2), Partition::Contiguous] {
            pool.install(|| in_place_pass(&mut f[base..], &lay, 9, 5, p, 2.0));
        }
        let back = lay.unpack(&f, 9, 37 * 5);
        assert!(back.iter().zip(&canon).all(|(b, c)| *b == 4.0 * c));
        // padding slots stay zero
        let total: f64 = f.iter().sum();
        assert_eq!(total, 4.0 * canon.iter().sum::<f64>());
    }
}
