//! Removing spheres from a running assembly (Ness et al. 2017: "particles flowing out of the end
//! of the die are removed from the simulation"). Histories are matched by index, so a removal
//! renumbers: the spheres after a removed one move down, and the pair list, the pair and
//! sphere-wall histories, the list's reference positions and the clumps' member lists are
//! remapped with them. The map is monotone, so the pair list stays sorted and every remaining
//! sphere's force is summed in the same order as in an assembly built without the removed ones
//! (`crates/dem/tests/removal.rs` checks it bit for bit).

use super::error::SphereError;
use super::law::SphereLaw;
use super::system::SphereSystem;
use crate::history::Histories;

/// Keep the entries of `v` whose `keep` is true, in order.
fn compact<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        keep[k - 1]
    });
}

impl SphereSystem {
    /// Remove the spheres `ids` (any order, repeats allowed); the others are renumbered in
    /// order. The contact histories are remapped in `law`'s record layout (records of another
    /// layout are dropped, as the stepper would reset them). Clump members cannot be removed
    /// one by one. The stored last forces of the remaining spheres are kept as they are: they
    /// include the pushes of removed spheres until the next force evaluation.
    pub fn remove_spheres<L: SphereLaw>(&mut self, _law: &L, ids: &[usize]) -> Result<(), SphereError> {
        let n = self.spheres.len();
        let mut keep = vec![true; n];
        for &k in ids {
            if k >= n {
                return Err(SphereError::NoSuchSphere { sphere: k, count: n });
            }
            if !self.is_free(k) {
                return Err(SphereError::ClumpMember {
                    sphere: k,
                    clump: self.spheres.owner[k] as usize,
                    action: "removed",
                });
            }
            keep[k] = false;
        }
        // New index of each kept sphere.
        let mut map = vec![u32::MAX; n];
        for (next, (m, _)) in map.iter_mut().zip(&keep).filter(|(_, k)| **k).enumerate() {
            *m = next as u32;
        }
        let s = &mut self.spheres;
        compact(&mut s.pos, &keep);
        compact(&mut s.vel, &keep);
        compact(&mut s.omega, &keep);
        compact(&mut s.force, &keep);
        compact(&mut s.torque, &keep);
        compact(&mut s.radius, &keep);
        compact(&mut s.mass, &keep);
        compact(&mut s.inertia, &keep);
        compact(&mut s.owner, &keep);
        compact(&mut s.frozen, &keep);

        let c = &mut self.contacts;
        let old = c
            .hist
            .as_slice::<L::History>()
            .filter(|h| h.len() == c.pairs.len());
        let mut pairs = Vec::with_capacity(c.pairs.len());
        let mut hist = Vec::with_capacity(c.pairs.len());
        for (k, p) in c.pairs.iter().enumerate() {
            let (i, j) = (p[0] as usize, p[1] as usize);
            if keep[i] && keep[j] {
                pairs.push([map[i], map[j]]);
                if let Some(h) = old {
                    hist.push(h[k]);
                }
            }
        }
        c.hist = match old {
            Some(_) => Histories::from_slice(&hist),
            None => Histories::default(),
        };
        c.pairs = pairs;
        // Rows of the sphere-wall records (sphere-major), if laid out for these walls.
        let nw = self.walls.len();
        c.wall_hist = match c.wall_hist.as_slice::<L::History>() {
            Some(w) if nw > 0 && c.wall_count == nw => {
                let rows: Vec<L::History> = w
                    .chunks_exact(nw)
                    .zip(&keep)
                    .filter(|(_, k)| **k)
                    .flat_map(|(r, _)| r.iter().copied())
                    .collect();
                Histories::from_slice(&rows)
            }
            _ => Histories::default(),
        };
        if c.list_ref.len() == n {
            compact(&mut c.list_ref, &keep);
        } else {
            // Stale already (spheres added since): the next step rebuilds the list.
            c.list_ref.clear();
        }
        for m in &mut self.clumps.members {
            *m = map[*m as usize];
        }
        Ok(())
    }
}
