//! Wall forces: the wall law between every circle and every wall (per circle in parallel), then
//! a sequential sum in circle order onto the bodies and the walls.

use super::Stepper;
use crate::contact::{ContactInput, ContactLaw};
use crate::system::System;
use crate::vector::Vec2;
use rayon::prelude::*;

impl Stepper {
    pub(super) fn wall_forces<W: ContactLaw>(&mut self, dt: f64, wall_law: &W, sys: &mut System) {
        let nw = sys.walls.len();
        if nw == 0 {
            return;
        }
        let (carm, cst) = (&self.carm, &self.cstate);
        let b = &sys.bodies;
        let walls = &sys.walls;
        let hist = sys.contacts.wall_hist.conform::<W::History>(b.n_circles() * nw);
        self.wall_buf.resize(b.n_circles() * nw, (Vec2::ZERO, 0.0));
        self.wall_buf
            .par_chunks_mut(nw)
            .zip(hist.par_chunks_mut(nw))
            .enumerate()
            .with_min_len(256)
            .for_each(|(c, (buf, hist))| {
                let k = b.circle_body[c] as usize;
                let r = b.circle_r[c];
                let range = wall_law.wall_range(r);
                for w in 0..nw {
                    match walls[w].touch_within(cst[c].pos, r, range) {
                        None => {
                            hist[w] = W::History::default();
                            buf[w] = (Vec2::ZERO, 0.0);
                        }
                        Some((delta, n)) => {
                            let a = r - delta;
                            let arm = carm[c] + n * a;
                            let v = b.vel[k] + arm.spin(b.omega[k]);
                            let ci = ContactInput {
                                delta,
                                n,
                                v_rel: v - walls[w].vel,
                                w_rel: b.omega[k],
                                r_eff: r,
                                m_eff: b.mass[k],
                                dt,
                            };
                            let o = wall_law.force(&ci, &mut hist[w]);
                            buf[w] = (o.f, arm.cross(o.f) + o.m_roll);
                        }
                    }
                }
            });
        let mut wf = vec![Vec2::ZERO; nw];
        let mut wn = vec![0u32; nw];
        let bodies = &mut sys.bodies;
        for c in 0..bodies.n_circles() {
            let k = bodies.circle_body[c] as usize;
            for (w, wfw) in wf.iter_mut().enumerate() {
                let (f, t) = self.wall_buf[c * nw + w];
                bodies.force[k] += f;
                bodies.torque[k] += t;
                *wfw -= f;
                wn[w] += u32::from(f != Vec2::ZERO);
            }
        }
        for ((w, f), n) in sys.walls.iter_mut().zip(wf).zip(wn) {
            w.force = f;
            w.n_contacts = n;
        }
    }
}
