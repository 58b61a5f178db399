//! Broad phase of the sphere engine: a linked-cell list (spheres counting-sorted by cell) builds
//! a Verlet pair list with a skin. Pairs come out sorted (i < j, ascending), whatever the order
//! the cells are visited in or how the spheres are shared among threads, so the force sums
//! downstream run in a fixed order. Periodic axes
//! use the minimum image; an axis with fewer than three cells visits each neighbour cell once.

use super::domain::Domain3;
use super::error::SphereError;
use super::system::FREE;
use crate::vector::{Vec3, Vector};
use rayon::prelude::*;

const MAX_CELLS: usize = 64 << 20;

/// Spheres per parallel task of the pair search.
const SPHERE_BLOCK: usize = 256;

/// Scratch of the cell list.
#[derive(Default, Debug, Clone)]
pub struct CellList3 {
    cell_start: Vec<u32>,
    sorted: Vec<u32>,
    cell: Vec<u32>,
    fill: Vec<u32>,
}

impl CellList3 {
    /// Into `pairs` (cleared first): the pairs (i < j, sorted) of spheres closer than
    /// r_i + r_j + range(r_i, r_j) + skin (centre distance, minimum image on periodic axes),
    /// leaving out pairs of the same clump (`owner`, [`FREE`] for a free sphere; an empty slice:
    /// every sphere free). `range` is the contact law's reach beyond touching
    /// ([`super::SphereLaw::range`]). A sphere outside the box on an open axis is refused.
    #[allow(clippy::too_many_arguments)]
    pub fn build_pairs(
        &mut self,
        dom: &Domain3,
        pos: &[Vec3],
        r: &[f64],
        owner: &[u32],
        skin: f64,
        range: impl Fn(f64, f64) -> f64 + Sync,
        pairs: &mut Vec<[u32; 2]>,
    ) -> Result<(), SphereError> {
        pairs.clear();
        let n = pos.len();
        for (k, &p) in pos.iter().enumerate() {
            for axis in (0..3).filter(|&a| !dom.periodic[a]) {
                let (v, lo, hi) = (p.component(axis), dom.lo.component(axis), dom.hi.component(axis));
                if !(v >= lo && v < hi) {
                    return Err(SphereError::OutsideBox {
                        sphere: k,
                        axis,
                        value: v,
                        lo,
                        hi,
                    });
                }
            }
        }
        let rmax = r.iter().copied().fold(0.0, f64::max);
        let cut = 2.0 * rmax + range(rmax, rmax) + skin;
        let size = dom.size();
        let mut nc = [1usize; 3];
        for (k, nk) in nc.iter_mut().enumerate() {
            let l = size.component(k);
            if dom.periodic[k] && l < 2.0 * cut {
                return Err(SphereError::PeriodicBoxTooSmall {
                    axis: k,
                    length: l,
                    cutoff: cut,
                });
            }
            *nk = if cut > 0.0 {
                ((l / cut).floor() as usize).max(1)
            } else {
                1
            };
        }
        let total = nc[0].saturating_mul(nc[1]).saturating_mul(nc[2]);
        if total > MAX_CELLS {
            return Err(SphereError::TooManyCells { cells: total });
        }
        let width = [
            size.x / nc[0] as f64,
            size.y / nc[1] as f64,
            size.z / nc[2] as f64,
        ];
        let index = |p: Vec3, k: usize| -> usize {
            let t = ((p.component(k) - dom.lo.component(k)) / width[k]).floor();
            (t.max(0.0) as usize).min(nc[k] - 1)
        };
        self.cell.clear();
        self.cell.extend(
            pos.iter()
                .map(|&p| ((index(p, 2) * nc[1] + index(p, 1)) * nc[0] + index(p, 0)) as u32),
        );
        self.cell_start.clear();
        self.cell_start.resize(total + 1, 0);
        for &c in &self.cell {
            self.cell_start[c as usize + 1] += 1;
        }
        for k in 0..total {
            self.cell_start[k + 1] += self.cell_start[k];
        }
        self.sorted.clear();
        self.sorted.resize(n, 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start[..total]);
        for (i, &c) in self.cell.iter().enumerate() {
            self.sorted[self.fill[c as usize] as usize] = i as u32;
            self.fill[c as usize] += 1;
        }
        // Neighbour indices along one axis: deduplicated, wrapped on a periodic axis; with
        // whether a neighbour was reached across a face.
        let axis_nb = |c: usize, k: usize| -> ([usize; 3], [bool; 3], usize) {
            let mut out = [0usize; 3];
            let mut across = [false; 3];
            let mut m = 0;
            for d in -1isize..=1 {
                let mut j = c as isize + d;
                let crossed = j < 0 || j >= nc[k] as isize;
                if dom.periodic[k] {
                    j = j.rem_euclid(nc[k] as isize);
                } else if crossed {
                    continue;
                }
                let j = j as usize;
                match out[..m].iter().position(|&o| o == j) {
                    Some(q) => across[q] |= crossed,
                    None => {
                        out[m] = j;
                        across[m] = crossed;
                        m += 1;
                    }
                }
            }
            (out, across, m)
        };
        // Lees-Edwards: the cells across a y face are displaced along x by the strain offset,
        // so a sphere whose y-neighbour layer lies across the face searches that layer's whole
        // x row (2 of every n_y layers do; the minimum image decides).
        let sheared = dom.shear.is_some();
        let (cell, cell_start, sorted) = (&self.cell, &self.cell_start, &self.sorted);
        // One sphere's partners j > i, ascending, appended to `out`.
        let partners = |i: usize, nb: &mut Vec<u32>, out: &mut Vec<[u32; 2]>| {
            let c = cell[i] as usize;
            let (cx, cy, cz) = (c % nc[0], (c / nc[0]) % nc[1], c / (nc[0] * nc[1]));
            let (xs, _, mx) = axis_nb(cx, 0);
            let (ys, y_across, my) = axis_nb(cy, 1);
            let (zs, _, mz) = axis_nb(cz, 2);
            nb.clear();
            let (pi, ri) = (pos[i], r[i]);
            for &z in &zs[..mz] {
                for (&y, &y_across) in ys[..my].iter().zip(&y_across[..my]) {
                    // The whole row (a range, nothing allocated), or the x neighbours.
                    let (row, nbs) = if sheared && y_across {
                        (0..nc[0], &[][..])
                    } else {
                        (0..0, &xs[..mx])
                    };
                    for x in row.chain(nbs.iter().copied()) {
                        let cc = (z * nc[1] + y) * nc[0] + x;
                        let members = cell_start[cc] as usize..cell_start[cc + 1] as usize;
                        for &j in &sorted[members] {
                            if (j as usize) <= i || same_clump(owner, i, j as usize) {
                                continue;
                            }
                            let d = dom.min_image(pos[j as usize] - pi);
                            let rj = r[j as usize];
                            let rc = ri + rj + range(ri, rj) + skin;
                            if d.norm2() < rc * rc {
                                nb.push(j);
                            }
                        }
                    }
                }
            }
            nb.sort_unstable();
            out.extend(nb.iter().map(|&j| [i as u32, j]));
        };
        // Spheres in blocks on rayon's threads, the blocks' pairs joined in sphere order: the
        // list is the serial one whatever the thread count.
        let blocks: Vec<Vec<[u32; 2]>> = (0..n.div_ceil(SPHERE_BLOCK))
            .into_par_iter()
            .map(|b| {
                let (mut nb, mut out) = (Vec::new(), Vec::new());
                for i in b * SPHERE_BLOCK..((b + 1) * SPHERE_BLOCK).min(n) {
                    partners(i, &mut nb, &mut out);
                }
                out
            })
            .collect();
        for b in &blocks {
            pairs.extend_from_slice(b);
        }
        Ok(())
    }
}

/// True if spheres `i` and `j` are members of the same clump.
#[inline]
fn same_clump(owner: &[u32], i: usize, j: usize) -> bool {
    !owner.is_empty() && owner[i] != FREE && owner[i] == owner[j]
}

/// Brute-force reference (all pairs, no range), for the test of the cell list.
#[cfg(test)]
fn brute_force_pairs(dom: &Domain3, pos: &[Vec3], r: &[f64], owner: &[u32], skin: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            if same_clump(owner, i, j) {
                continue;
            }
            let rc = r[i] + r[j] + skin;
            if dom.min_image(pos[j] - pos[i]).norm2() < rc * rc {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn no_range(_: f64, _: f64) -> f64 {
        0.0
    }

    #[test]
    fn cell_list_matches_brute_force_for_every_periodicity() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(19);
        let hi = Vec3::new(1.0, 0.6, 0.45);
        let pos: Vec<Vec3> = (0..600)
            .map(|_| {
                Vec3::new(
                    rng.random::<f64>(),
                    0.6 * rng.random::<f64>(),
                    0.45 * rng.random::<f64>(),
                )
            })
            .collect();
        let r: Vec<f64> = (0..600).map(|_| 0.02 + 0.03 * rng.random::<f64>()).collect();
        let mut cl = CellList3::default();
        for mask in 0..8u8 {
            let periodic = [mask & 1 != 0, mask & 2 != 0, mask & 4 != 0];
            let dom = Domain3::new(Vec3::ZERO, hi, periodic).unwrap();
            let mut got = Vec::new();
            cl.build_pairs(&dom, &pos, &r, &[], 0.01, no_range, &mut got)
                .unwrap();
            let want = brute_force_pairs(&dom, &pos, &r, &[], 0.01);
            assert!(!want.is_empty());
            assert_eq!(got, want, "periodic {periodic:?}");
            // Spheres grouped in threes into clumps (every fourth one free): no pair inside a
            // clump, the others as before.
            let owner: Vec<u32> = (0..600u32)
                .map(|k| if k % 4 == 3 { FREE } else { k / 12 })
                .collect();
            cl.build_pairs(&dom, &pos, &r, &owner, 0.01, no_range, &mut got)
                .unwrap();
            let want_c = brute_force_pairs(&dom, &pos, &r, &owner, 0.01);
            assert_eq!(got, want_c, "periodic {periodic:?}, clumps");
            let inside = want
                .iter()
                .filter(|p| owner[p[0] as usize] != FREE && owner[p[0] as usize] == owner[p[1] as usize])
                .count();
            assert!(inside > 0 && want_c.len() + inside == want.len());
            // A law with a range of 0.3 (r_i + r_j) reaches as far as a skin that large.
            let ranged = |a: f64, b: f64| 0.3 * (a + b);
            cl.build_pairs(&dom, &pos, &r, &[], 0.01, ranged, &mut got)
                .unwrap();
            let want_r: Vec<[u32; 2]> = brute_force_pairs(&dom, &pos, &r, &[], 0.3)
                .into_iter()
                .filter(|&[i, j]| {
                    let (i, j) = (i as usize, j as usize);
                    let rc = 1.3 * (r[i] + r[j]) + 0.01;
                    dom.min_image(pos[j] - pos[i]).norm2() < rc * rc
                })
                .collect();
            assert!(want_r.len() > want.len());
            assert_eq!(got, want_r, "periodic {periodic:?}, with a range");
        }
        // Lees-Edwards boxes (x and y periodic, z either), at several offsets and with 5 and
        // 2 cell layers along y: the sheared minimum image, and no pair missed across the
        // displaced faces.
        for (ly, periodic_z) in [(0.6, false), (0.6, true), (0.25, true)] {
            let hi = Vec3::new(1.0, ly, 0.45);
            let pos_y: Vec<Vec3> = pos.iter().map(|p| Vec3::new(p.x, p.y * ly / 0.6, p.z)).collect();
            for offset in [0.0, 0.013, 0.37, 0.5, 0.93] {
                let mut dom = Domain3::new(Vec3::ZERO, hi, [true, true, periodic_z])
                    .unwrap()
                    .with_lees_edwards(0.7)
                    .unwrap();
                dom.shear.as_mut().unwrap().offset = offset;
                let mut got = Vec::new();
                cl.build_pairs(&dom, &pos_y, &r, &[], 0.01, no_range, &mut got)
                    .unwrap();
                let want = brute_force_pairs(&dom, &pos_y, &r, &[], 0.01);
                // Pairs across the sheared faces are there (some with the x shift).
                let across = want
                    .iter()
                    .filter(|&&[i, j]| (pos_y[j as usize].y - pos_y[i as usize].y).abs() > 0.5 * ly)
                    .count();
                assert!(across > 0, "offset {offset}");
                assert_eq!(got, want, "Lees-Edwards, L_y {ly}, offset {offset}");
            }
        }
        // An axis too short for a unique minimum image is refused.
        let dom = Domain3::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.2), [false, false, true]).unwrap();
        let err = cl
            .build_pairs(&dom, &pos, &r, &[], 0.01, no_range, &mut Vec::new())
            .unwrap_err();
        assert!(
            matches!(err, SphereError::PeriodicBoxTooSmall { axis: 2, .. }),
            "{err}"
        );
        // A sphere outside the box on an open axis is refused, naming it.
        let dom = Domain3::new(Vec3::ZERO, hi, [true, false, true]).unwrap();
        let mut out = pos.clone();
        out[7].y = 0.6;
        let err = cl
            .build_pairs(&dom, &out, &r, &[], 0.01, no_range, &mut Vec::new())
            .unwrap_err();
        assert!(
            matches!(
                err,
                SphereError::OutsideBox {
                    sphere: 7,
                    axis: 1,
                    ..
                }
            ),
            "{err}"
        );
    }
}
