//! Broad phase: a cell list (circles counting-sorted by cell) builds a Verlet pair list with a
//! skin. Pairs are kept in canonical order (i < j, sorted), so the per-particle gather sums in
//! a fixed order whatever the thread count or the step at which the list was rebuilt; the
//! history of each pair (whatever the law's history type) is carried over to the new list by a
//! merge.

use crate::domain::Domain;
use crate::error::DemError;
use crate::history::Histories;
use crate::vector::Vec2;
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Persistent contacts: the candidate pairs and their history (plain data, checkpointed).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Contacts {
    pub pairs: Vec<[u32; 2]>,
    /// History of each pair under the pair law (`hist.as_slice::<L::History>()`).
    pub hist: Histories,
    /// History of circle-wall contacts under the wall law, `c * n_walls + w`.
    pub wall_hist: Histories,
}

impl Contacts {
    /// Pairs whose history is not the fresh state (some slot != 0.0), with their raw history
    /// slots, in list order: the pairs in contact (or in range) that carry state. Pairs that do
    /// not interact carry no history, so two runs that differ only in their candidate lists
    /// give the same sequence.
    pub fn pairs_with_history(&self) -> impl Iterator<Item = ([u32; 2], &[f64])> + '_ {
        self.pairs
            .iter()
            .zip(self.hist.records())
            .filter(|(_, h)| h.iter().any(|&x| x != 0.0))
            .map(|(p, h)| (*p, h))
    }
}

/// Fixed chunk of circles per parallel task while building the list.
const BUILD_CHUNK: usize = 2048;
const MAX_CELLS: usize = 64 << 20;

/// Scratch of the cell list.
#[derive(Default, Debug, Clone)]
pub struct CellList {
    ncell: [usize; 2],
    cell_start: Vec<u32>,
    sorted: Vec<u32>,
}

impl CellList {
    /// Build the pair list for circles at `pos` with radii `r` (pairs closer than
    /// r_i + r_j + skin; circles of the same body excluded).
    pub fn build_pairs(
        &mut self,
        dom: &Domain,
        pos: &[Vec2],
        r: &[f64],
        body: &[u32],
        skin: f64,
    ) -> Result<Vec<[u32; 2]>, DemError> {
        self.build_pairs_in_range(dom, pos, r, body, skin, |_, _| 0.0)
    }

    /// [`CellList::build_pairs`] for a law acting across gaps up to `range(r_i, r_j)`: pairs
    /// closer than r_i + r_j + range + skin (`range` non-decreasing in the radii).
    pub fn build_pairs_in_range(
        &mut self,
        dom: &Domain,
        pos: &[Vec2],
        r: &[f64],
        body: &[u32],
        skin: f64,
        range: impl Fn(f64, f64) -> f64 + Sync,
    ) -> Result<Vec<[u32; 2]>, DemError> {
        let n = pos.len();
        let rmax = r.iter().copied().fold(0.0, f64::max);
        let cut = 2.0 * rmax + range(rmax, rmax) + skin;
        let size = dom.size();
        let nx = ((size.x / cut).floor() as usize).max(1);
        let ny = ((size.y / cut).floor() as usize).max(1);
        if nx.saturating_mul(ny) > MAX_CELLS {
            return Err(DemError::TooManyCells {
                cells: nx.saturating_mul(ny),
            });
        }
        self.ncell = [nx, ny];
        let (cx, cy) = (size.x / nx as f64, size.y / ny as f64);
        let cell_of = |p: Vec2| -> usize {
            let ix = (((p.x - dom.lo.x) / cx).floor().max(0.0) as usize).min(nx - 1);
            let iy = (((p.y - dom.lo.y) / cy).floor().max(0.0) as usize).min(ny - 1);
            iy * nx + ix
        };
        let cells: Vec<u32> = pos.par_iter().map(|&p| cell_of(p) as u32).collect();
        self.cell_start.clear();
        self.cell_start.resize(nx * ny + 1, 0);
        for &c in &cells {
            self.cell_start[c as usize + 1] += 1;
        }
        for k in 0..nx * ny {
            self.cell_start[k + 1] += self.cell_start[k];
        }
        self.sorted.clear();
        self.sorted.resize(n, 0);
        let mut fill = self.cell_start.clone();
        for (i, &c) in cells.iter().enumerate() {
            self.sorted[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        let search = Search {
            dom,
            nx,
            ny,
            cells: &cells,
            cs: &self.cell_start,
            sorted: &self.sorted,
            pos,
            r,
            body,
            skin,
            range: &range,
        };
        let chunks: Vec<Vec<[u32; 2]>> = (0..n.div_ceil(BUILD_CHUNK))
            .into_par_iter()
            .map(|k| simd::dispatch(SearchChunk { s: &search, k }))
            .collect();
        Ok(chunks.concat())
    }
}

/// What the pair search of one chunk of circles reads.
struct Search<'a, R> {
    dom: &'a Domain,
    nx: usize,
    ny: usize,
    cells: &'a [u32],
    cs: &'a [u32],
    sorted: &'a [u32],
    pos: &'a [Vec2],
    r: &'a [f64],
    body: &'a [u32],
    skin: f64,
    range: &'a R,
}

/// The pairs (i, j > i) of circles `k BUILD_CHUNK..(k + 1) BUILD_CHUNK`, in order; one op of
/// `lbdem_core::simd::dispatch`.
struct SearchChunk<'a, 'b, R> {
    s: &'b Search<'a, R>,
    k: usize,
}

impl<R: Fn(f64, f64) -> f64 + Sync> WithSimd for SearchChunk<'_, '_, R> {
    type Output = Vec<[u32; 2]>;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> Vec<[u32; 2]> {
        let Search {
            dom,
            nx,
            ny,
            cells,
            cs,
            sorted,
            pos,
            r,
            body,
            skin,
            range,
        } = *self.s;
        let (k, n) = (self.k, pos.len());
        let mut out = Vec::new();
        let mut nb: Vec<u32> = Vec::new();
        // Neighbour cells, deduplicated when a periodic axis has fewer than 3 cells.
        let mut ncells: Vec<usize> = Vec::with_capacity(9);
        for i in k * BUILD_CHUNK..((k + 1) * BUILD_CHUNK).min(n) {
            let c = cells[i] as usize;
            let (ix, iy) = ((c % nx) as isize, (c / nx) as isize);
            ncells.clear();
            for dy in -1..=1isize {
                for dx in -1..=1isize {
                    let (mut jx, mut jy) = (ix + dx, iy + dy);
                    if dom.periodic[0] {
                        jx = jx.rem_euclid(nx as isize);
                    } else if jx < 0 || jx >= nx as isize {
                        continue;
                    }
                    if dom.periodic[1] {
                        jy = jy.rem_euclid(ny as isize);
                    } else if jy < 0 || jy >= ny as isize {
                        continue;
                    }
                    let cc = jy as usize * nx + jx as usize;
                    if !ncells.contains(&cc) {
                        ncells.push(cc);
                    }
                }
            }
            nb.clear();
            let (pi, ri, bi) = (pos[i], r[i], body[i]);
            for &cc in &ncells {
                for &j in &sorted[cs[cc] as usize..cs[cc + 1] as usize] {
                    if (j as usize) <= i || body[j as usize] == bi {
                        continue;
                    }
                    let d = dom.min_image(pos[j as usize] - pi);
                    let rj = r[j as usize];
                    let rc = ri + rj + range(ri, rj) + skin;
                    if d.x * d.x + d.y * d.y < rc * rc {
                        nb.push(j);
                    }
                }
            }
            nb.sort_unstable();
            out.extend(nb.iter().map(|&j| [i as u32, j]));
        }
        out
    }
}

/// Carry history from `(old_pairs, old_hist)` onto `new_pairs` (both sorted); new pairs start empty.
pub fn carry_history<H: Copy + Default>(
    old_pairs: &[[u32; 2]],
    old_hist: &[H],
    new_pairs: &[[u32; 2]],
) -> Vec<H> {
    let mut out = vec![H::default(); new_pairs.len()];
    carry_history_into(old_pairs, old_hist, new_pairs, &mut out);
    out
}

/// [`carry_history`] into `out` (one record per new pair, already fresh). Old pairs without a
/// history record (a short `old_hist`) carry nothing.
pub fn carry_history_into<H: Copy>(
    old_pairs: &[[u32; 2]],
    old_hist: &[H],
    new_pairs: &[[u32; 2]],
    out: &mut [H],
) {
    let mut k = 0;
    for (p, h) in new_pairs.iter().zip(out.iter_mut()) {
        while k < old_pairs.len() && old_pairs[k] < *p {
            k += 1;
        }
        if k < old_pairs.len()
            && old_pairs[k] == *p
            && let Some(o) = old_hist.get(k)
        {
            *h = *o;
        }
    }
}

/// Brute-force reference (all pairs), for tests of the cell list.
pub fn brute_force_pairs(dom: &Domain, pos: &[Vec2], r: &[f64], body: &[u32], skin: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            if body[i] == body[j] {
                continue;
            }
            let d = dom.min_image(pos[j] - pos[i]);
            let rc = r[i] + r[j] + skin;
            if d.x * d.x + d.y * d.y < rc * rc {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}
