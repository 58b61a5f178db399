//! Wall forces: the wall law between the walls and the circles near them, in circle order, onto
//! the bodies and the walls.
//!
//! A sample's walls touch few of its circles (the push-plate of Su's shear cell: about 1 % of
//! them), so the pass keeps the circles that may reach a wall (`Stepper::wall_near`), searched
//! when the pair list is rebuilt or a wall has moved by half the skin since the last search. The
//! search reaches the law's reach plus 1.5 skins: until the next list rebuild every circle stays
//! within half a skin of where the list was built, so within one skin of where the search saw it,
//! and the walls within half a skin of theirs. Every other circle's wall history stays fresh.
//! Only touching circles add to the sums, in ascending circle order: the result does not depend
//! on when the search ran.

use super::Stepper;
use crate::contact::{ContactInput, ContactLaw};
use crate::system::System;
use crate::vector::Vec2;

impl Stepper {
    /// The search: the circles that may reach a wall before the next one (`wall_near`), and
    /// fresh wall histories for every other circle (they touch no wall now). Called by the
    /// pair-list rebuild and, when a wall has moved half the skin, by [`Stepper::wall_forces`].
    pub(super) fn find_wall_circles<W: ContactLaw>(&mut self, sys: &mut System, skin: f64, wall_law: &W) {
        let (nc, nw) = (sys.bodies.n_circles(), sys.walls.len());
        self.wall_near.clear();
        self.wall_ref.clone_from(&sys.walls);
        if nw == 0 {
            return;
        }
        let hist = sys.contacts.wall_hist.conform::<W::History>(nc * nw);
        let b = &sys.bodies;
        for c in 0..nc {
            let (pos, r) = (self.cstate[c].pos, b.circle_r[c]);
            let reach = r + wall_law.wall_range(r) + 1.5 * skin;
            if sys.walls.iter().any(|w| w.may_touch(pos, reach)) {
                self.wall_near.push(c as u32);
            } else {
                hist[c * nw..(c + 1) * nw].fill(W::History::default());
            }
        }
    }

    pub(super) fn wall_forces<W: ContactLaw>(&mut self, dt: f64, skin: f64, wall_law: &W, sys: &mut System) {
        let nw = sys.walls.len();
        if nw == 0 {
            return;
        }
        let moved = self.wall_ref.len() != nw
            || self.wall_ref.iter().zip(&sys.walls).any(|(r, w)| {
                let d = w.moved_from(r);
                d.is_nan() || d > 0.5 * skin
            });
        if moved {
            self.find_wall_circles(sys, skin, wall_law);
        }
        let hist = sys
            .contacts
            .wall_hist
            .conform::<W::History>(sys.bodies.n_circles() * nw);
        let mut wf = vec![Vec2::ZERO; nw];
        let mut wn = vec![0u32; nw];
        let (carm, cst) = (&self.carm, &self.cstate);
        let b = &mut sys.bodies;
        for &c in &self.wall_near {
            let c = c as usize;
            let k = b.circle_body[c] as usize;
            let r = b.circle_r[c];
            let range = wall_law.wall_range(r);
            for (w, wall) in sys.walls.iter().enumerate() {
                let h = &mut hist[c * nw + w];
                let Some((delta, n)) = wall.touch_within(cst[c].pos, r, range) else {
                    *h = W::History::default();
                    continue;
                };
                let a = r - delta;
                let arm = carm[c] + n * a;
                let v = b.vel[k] + arm.spin(b.omega[k]);
                let ci = ContactInput {
                    delta,
                    n,
                    v_rel: v - wall.vel,
                    w_rel: b.omega[k],
                    r_eff: r,
                    m_eff: b.mass[k],
                    dt,
                };
                let o = wall_law.force(&ci, h);
                b.force[k] += o.f;
                b.torque[k] += arm.cross(o.f) + o.m_roll;
                wf[w] -= o.f;
                wn[w] += u32::from(o.f != Vec2::ZERO);
            }
        }
        for ((w, f), n) in sys.walls.iter_mut().zip(wf).zip(wn) {
            w.force = f;
            w.n_contacts = n;
        }
    }
}
