//! Padded storage layout of the in-place AA kernel's population array.
//!
//! With the canonical layout `f[i * n + node]` the nine (nineteen) direction arrays of a power-of-
//! two grid start at addresses that differ by a multiple of 4 KiB, and so do neighbouring rows of
//! one array: every stream of the kernel then maps to the same L1 set and the loads suffer 4K
//! aliasing. At 1024² the AA kernel ran at about 55 % of the in-place memory ceiling against
//! about 78 % at 1000² (same run, `examples/mlups.rs`). The AA stepper therefore keeps its
//! array padded: a row takes `nxp >= nx` slots (one extra cache line when a row is a multiple of
//! 512 bytes) and direction i starts at `i * stride`, with `stride` a multiple of 4 KiB plus seven
//! cache lines, so that the 3 rows × Q directions touched around a node fall into distinct sets.
//! Rows are also rounded up to whole cache lines and the first slot is placed on a 64-byte
//! boundary (`base`), so that the even step's blocks load and store whole lines.
//! The padding slots are never read or written by the kernel.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Nodes per row.
    pub nx: usize,
    /// Slots per row (>= nx).
    pub nxp: usize,
    /// Slots per direction array (>= nxp × rows).
    pub stride: usize,
    /// Slots of the vector before slot 0 (set by `pack` to align slot 0 to 64 bytes).
    pub base: usize,
}

impl Layout {
    /// The unpadded layout (`nxp = nx`, `stride = n`).
    pub fn canonical(n: [usize; 3]) -> Self {
        Self {
            nx: n[0],
            nxp: n[0],
            stride: n[0] * n[1] * n[2],
            base: 0,
        }
    }

    /// The padded layout for stored values of `T` (see the module doc).
    pub fn padded<T>(n: [usize; 3]) -> Self {
        let size = std::mem::size_of::<T>();
        let line = 64 / size;
        let nxp = n[0].next_multiple_of(line);
        let nxp = if (nxp * size).is_multiple_of(512) {
            nxp + line
        } else {
            nxp
        };
        let page = 4096 / size;
        let cells = nxp * n[1] * n[2];
        Self {
            nx: n[0],
            nxp,
            stride: cells.div_ceil(page) * page + 7 * line,
            base: 0,
        }
    }

    /// Slot of direction `i` at node `node` (canonical node index x + nx (y + ny z)), counted from
    /// slot 0 (index `base + slot` in the vector).
    #[inline(always)]
    pub fn slot(&self, i: usize, node: usize) -> usize {
        i * self.stride + node + (node / self.nx) * (self.nxp - self.nx)
    }

    /// Slot of direction `i` at x of row `r`.
    #[inline(always)]
    pub fn row_slot(&self, i: usize, r: usize, x: usize) -> usize {
        i * self.stride + r * self.nxp + x
    }

    /// Copy `q` canonical arrays of `n` values into this layout (padding slots zero) and set
    /// `base` so that slot 0 of the new vector is 64-byte aligned.
    pub fn pack<T: Copy + Default>(&mut self, f: &[T], q: usize) -> Vec<T> {
        let n = f.len() / q;
        let size = std::mem::size_of::<T>();
        let mut out = vec![T::default(); q * self.stride + 64 / size];
        let mis = out.as_ptr() as usize % 64;
        self.base = (64 - mis) % 64 / size;
        for i in 0..q {
            for (r, row) in f[i * n..(i + 1) * n].chunks_exact(self.nx).enumerate() {
                let s = self.base + self.row_slot(i, r, 0);
                out[s..s + self.nx].copy_from_slice(row);
            }
        }
        out
    }

    /// Inverse of `pack`: `q` canonical arrays of `n` values.
    pub fn unpack<T: Copy + Default>(&self, f: &[T], q: usize, n: usize) -> Vec<T> {
        let mut out = vec![T::default(); q * n];
        for i in 0..q {
            for (r, row) in out[i * n..(i + 1) * n].chunks_exact_mut(self.nx).enumerate() {
                let s = self.base + self.row_slot(i, r, 0);
                row.copy_from_slice(&f[s..s + self.nx]);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pack_unpack_round_trip_and_slots_agree() {
        for n in [[1024, 4, 1], [37, 5, 3], [256, 192, 1]] {
            let cells = n[0] * n[1] * n[2];
            let f: Vec<f64> = (0..9 * cells).map(|k| k as f64).collect();
            for mut lay in [
                Layout::padded::<f64>(n),
                Layout::padded::<f32>(n),
                Layout::canonical(n),
            ] {
                assert!(lay.nxp >= n[0] && lay.stride >= lay.nxp * n[1] * n[2]);
                let p = lay.pack(&f, 9);
                assert_eq!((p.as_ptr() as usize + 8 * lay.base) % 64, 0);
                for i in 0..9 {
                    for node in [0, 1, n[0] - 1, n[0], cells - 1] {
                        assert_eq!(p[lay.base + lay.slot(i, node)], f[i * cells + node]);
                    }
                }
                assert_eq!(lay.unpack(&p, 9, cells), f);
            }
        }
        // a power-of-two row gets a padding line; array starts are not 4 KiB apart
        let lay = Layout::padded::<f64>([1024, 1024, 1]);
        assert_eq!(lay.nxp, 1032);
        assert_eq!(Layout::padded::<f64>([1000, 4, 1]).nxp, 1000);
        assert_eq!(Layout::padded::<f32>([37, 4, 1]).nxp, 48);
        assert_ne!((lay.stride * 8) % 4096, 0);
    }
}
