//! The lane code of the sphere engine's half kick and drift (`spheres::stepper::kick`), eight
//! spheres per instruction, written once against a lane type `super::lanes` and compiled for
//! each (`crate::on_avx512`, `crate::on_arrays`). The same IEEE operations as the scalar kick
//! (v += F (h/m), ω += T (h/I), x + v dt); the wrap into the box stays scalar and is taken only
//! by the spheres whose new position left it on a periodic axis (for the others the scalar
//! `Domain3::wrap_moving` changes nothing), so the bits are the scalar kick's.

use super::lanes::{self, F8};
use crate::lanes::W;
use crate::spheres::domain::Domain3;
use crate::spheres::kick_batched::KickInput;
use crate::vector::{Vec3, Vector};

/// The spheres `first..first + pos.len()`: their positions, velocities and spins updated.
#[inline(always)]
pub(crate) fn run(inp: &KickInput, first: usize, pos: &mut [Vec3], vel: &mut [Vec3], omega: &mut [Vec3]) {
    let n = pos.len();
    let whole = n - n % W;
    let one = F8::splat(1.0);
    let h = F8::splat(inp.h);
    for q in (0..whole).step_by(W) {
        let g = first + q;
        let mobile = eight(inp.mobile, g).ge(one);
        let (f, t) = (three(inp.force, g), three(inp.torque, g));
        let sv = h / eight(inp.mass, g);
        let sw = h / eight(inp.inertia, g);
        let vr: &mut [Vec3; W] = (&mut vel[q..q + W]).try_into().expect("eight velocities");
        let vr: &mut [[f64; 3]; W] = bytemuck::cast_mut(vr);
        let v = lanes::load3(vr);
        let v = step3(mobile, v, f, sv);
        lanes::store3(vr, v);
        let wr: &mut [Vec3; W] = (&mut omega[q..q + W]).try_into().expect("eight spins");
        let wr: &mut [[f64; 3]; W] = bytemuck::cast_mut(wr);
        let w = lanes::load3(wr);
        let w = step3(mobile, w, t, sw);
        lanes::store3(wr, w);
        if let Some((dt, _)) = inp.drift {
            let xr: &mut [Vec3; W] = (&mut pos[q..q + W]).try_into().expect("eight positions");
            let xr: &mut [[f64; 3]; W] = bytemuck::cast_mut(xr);
            let x = lanes::load3(xr);
            let dt = F8::splat(dt);
            let x = step3(mobile, x, v, dt);
            lanes::store3(xr, x);
        }
    }
    // The tail, and the wrap of every sphere that left the box, as the scalar kick.
    for k in whole..n {
        let g = first + k;
        if inp.mobile[g] < 1.0 {
            continue;
        }
        vel[k] += inp.force[g] * (inp.h / inp.mass[g]);
        omega[k] += inp.torque[g] * (inp.h / inp.inertia[g]);
        if let Some((dt, _)) = inp.drift {
            pos[k] += vel[k] * dt;
        }
    }
    if let Some((_, dom)) = inp.drift {
        for k in 0..n {
            if inp.mobile[first + k] >= 1.0 && !inside(dom, pos[k]) {
                (pos[k], vel[k]) = dom.wrap_moving(pos[k], vel[k]);
            }
        }
    }
}

/// `a + b s` where `mobile`, else `a`, per component (a function, not `from_fn` with a
/// closure: a closure is compiled without the lane copy's target features).
#[inline(always)]
fn step3(mobile: lanes::M8, a: [F8; 3], b: [F8; 3], s: F8) -> [F8; 3] {
    [
        mobile.select(a[0] + b[0] * s, a[0]),
        mobile.select(a[1] + b[1] * s, a[1]),
        mobile.select(a[2] + b[2] * s, a[2]),
    ]
}

/// Lanes `a[g..g + 8]` (a function, not a closure: a closure is compiled without the target
/// features of the AVX-512 copy, and its intrinsics would stay calls).
#[inline(always)]
fn eight(a: &[f64], g: usize) -> F8 {
    F8::from_array(a[g..g + W].try_into().expect("eight values"))
}

/// x, y, z lanes of `a[g..g + 8]`.
#[inline(always)]
fn three(a: &[Vec3], g: usize) -> [F8; 3] {
    let a: &[Vec3; W] = a[g..g + W].try_into().expect("eight vectors");
    lanes::load3(bytemuck::cast_ref(a))
}

/// Inside `[lo, hi)` on every periodic axis: `Domain3::wrap_moving` leaves such a point (and
/// its velocity) as it is.
#[inline(always)]
fn inside(dom: &Domain3, p: Vec3) -> bool {
    // A Lees-Edwards box wraps y whatever its periodic flags say.
    let periodic = [
        dom.periodic[0],
        dom.periodic[1] || dom.shear.is_some(),
        dom.periodic[2],
    ];
    let ok = |k: usize, x: f64| !periodic[k] || (x >= dom.lo.component(k) && x < dom.hi.component(k));
    ok(0, p.x) && ok(1, p.y) && ok(2, p.z)
}
