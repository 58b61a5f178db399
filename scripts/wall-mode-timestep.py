#!/usr/bin/env python3
"""An independent check of the wall-contact step limit (crates/dem/src/stepper/wall_modes.rs):
time-steps the linearised grain of the reduced Float case that crept along the top wall (body 82,
two circles r = 35 and 30 um both on the wall; area 0.5268 kg/m² x its union) with the stepper's
kick-drift-kick scheme, dashpots reading the half-step velocity, and bisects the step at which a
1 nm push stops decaying within 20 000 steps.

    python3 scripts/wall-mode-timestep.py [DAMPING_RATIO]      (default 0.5)

Printed 2026-11-28: 5.759e-06 s (0.5), 8.124e-06 s (0.25), 1.024e-05 s (0.1); the Rust test
`cargo test -p lbdem-dem --lib the_creeping_float_grain` asserts the eigenvalue form within 5e-4 (2.5e-4 measured).
"""
import math
import sys

CIRCLES = [(0.000427193, 0.001165, 35e-6), (0.000461834, 0.00117, 30e-6)]
RHO, K_N, K_T, WALL_Y = 0.5268, 31.1, 15.55, 0.0012


def mass_properties(n=400):
    x0 = min(x - r for x, _, r in CIRCLES)
    x1 = max(x + r for x, _, r in CIRCLES)
    y0 = min(y - r for _, y, r in CIRCLES)
    y1 = max(y + r for _, y, r in CIRCLES)
    dx, dy = (x1 - x0) / n, (y1 - y0) / n
    pts = []
    for i in range(n):
        for j in range(n):
            px, py = x0 + (i + 0.5) * dx, y0 + (j + 0.5) * dy
            if any((px - a) ** 2 + (py - b) ** 2 < r * r for a, b, r in CIRCLES):
                pts.append((px, py))
    area = len(pts) * dx * dy
    cx = sum(p[0] for p in pts) / len(pts)
    cy = sum(p[1] for p in pts) / len(pts)
    inertia = RHO * dx * dy * sum((px - cx) ** 2 + (py - cy) ** 2 for px, py in pts)
    return RHO * area, inertia, cx, cy


def amplitude(h, m, inertia, arms, cn, ct, steps=20000):
    q, v = [0.0, 1e-9, 0.0], [0.0, 0.0, 0.0]
    mass = [m, m, inertia]

    def force():
        f = [0.0, 0.0, 0.0]
        for ax, ay in arms:
            dpx, dpy = q[0] - q[2] * ay, q[1] + q[2] * ax
            vpx, vpy = v[0] - v[2] * ay, v[1] + v[2] * ax
            fx, fy = -K_T * dpx - ct * vpx, -K_N * dpy - cn * vpy
            f[0] += fx
            f[1] += fy
            f[2] += ax * fy - ay * fx
        return f

    f = force()
    for _ in range(steps):
        for k in range(3):
            v[k] += 0.5 * h * f[k] / mass[k]
            q[k] += h * v[k]
        f = force()
        for k in range(3):
            v[k] += 0.5 * h * f[k] / mass[k]
        a = max(abs(q[0]), abs(q[1]), abs(q[2]) * 50e-6)
        if not a < 1.0:
            return math.inf
    return a


def main():
    zeta = float(sys.argv[1]) if len(sys.argv) > 1 else 0.5
    m, inertia, cx, cy = mass_properties()
    arms = [(x - cx, WALL_Y - cy) for x, _, _ in CIRCLES]
    cn = 2.0 * zeta * math.sqrt(K_N * m)
    lo, hi = 1e-7, 2e-5
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if amplitude(mid, m, inertia, arms, cn, 0.5 * cn) < 1e-8:
            lo = mid
        else:
            hi = mid
    print(f"m = {m:.4e} kg, I = {inertia:.4e} kg m², damping ratio {zeta}: largest stable step {lo:.4e} s")


if __name__ == "__main__":
    main()
