//! Verlet-list rebuild: the pair list (reaching each pair law's range), the histories carried
//! onto it, and the index tables of the per-circle gather and the fused disk pass.

use super::{CIRCLE_CHUNK, Stepper};
use crate::contact::ContactLaw;
use crate::error::DemError;
use crate::history::Histories;
use crate::neighbor::carry_history_into;
use crate::scratch::PairOut;
use crate::system::System;

impl Stepper {
    pub(super) fn rebuild<L: ContactLaw, W: ContactLaw>(
        &mut self,
        sys: &mut System,
        skin: f64,
        law: &L,
        wall_law: &W,
    ) -> Result<(), DemError> {
        let b = &sys.bodies;
        if self.all_disks {
            self.cpos.clear();
            self.cpos.extend(self.cstate.iter().map(|c| c.pos));
        }
        let pairs = self.cells.build_pairs_in_range(
            &sys.domain,
            &self.cpos,
            &b.circle_r,
            &b.circle_body,
            skin,
            |ri, rj| law.range(ri, rj),
        )?;
        // Histories of the pairs still in the list carry over (a store of another layout, from
        // another law, starts afresh).
        let mut hist = Histories::default();
        let fresh = hist.conform::<L::History>(pairs.len());
        if let Some(old) = sys.contacts.hist.as_slice::<L::History>()
            && old.len() == sys.contacts.pairs.len()
        {
            carry_history_into(&sys.contacts.pairs, old, &pairs, fresh);
        }
        sys.contacts.pairs = pairs;
        sys.contacts.hist = hist;
        sys.contacts
            .wall_hist
            .resize::<W::History>(b.n_circles() * sys.walls.len());
        self.ref_pos.clone_from(&self.cpos);
        // Pairs of each circle as i (contiguous: the list is sorted), and as j (ascending i).
        let nc = b.n_circles();
        let pairs = &sys.contacts.pairs;
        self.pair_start.clear();
        self.pair_start.resize(nc + 1, 0);
        self.j_start.clear();
        self.j_start.resize(nc + 1, 0);
        for pr in pairs {
            self.pair_start[pr[0] as usize + 1] += 1;
            self.j_start[pr[1] as usize + 1] += 1;
        }
        for c in 0..nc {
            self.pair_start[c + 1] += self.pair_start[c];
            self.j_start[c + 1] += self.j_start[c];
        }
        self.j_list.clear();
        self.j_list.resize(pairs.len(), 0);
        let mut fill: Vec<u32> = self.j_start[..nc].to_vec();
        for (k, pr) in pairs.iter().enumerate() {
            let c = pr[1] as usize;
            self.j_list[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        self.out.resize(pairs.len(), PairOut::default());
        self.touch.resize(pairs.len(), 0);
        // Circles whose lowest partner i lies in an earlier chunk than their own.
        self.deferred.clear();
        self.deferred_start.clear();
        for c0 in (0..nc).step_by(CIRCLE_CHUNK) {
            self.deferred_start.push(self.deferred.len() as u32);
            for c in c0..(c0 + CIRCLE_CHUNK).min(nc) {
                let (a, b) = (self.j_start[c] as usize, self.j_start[c + 1] as usize);
                if a < b && (pairs[self.j_list[a] as usize][0] as usize) < c0 {
                    self.deferred.push(c as u32);
                }
            }
        }
        self.deferred_start.push(self.deferred.len() as u32);
        self.find_wall_circles(sys, skin, wall_law);
        self.rebuilds += 1;
        Ok(())
    }
}
