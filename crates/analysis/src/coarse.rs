//! Binned coarse-graining of a sphere assembly in a pseudo-2D channel (Ness et al. 2017,
//! "Simulation cases studied": bins of d × d × 5 d on a regular grid in the x-y plane; a
//! particle's velocity and force-dipole share go to the bin holding its centre; velocities are
//! averaged per bin, dipoles summed and divided by the bin volume, Eq. 7).
//!
//! Time averages over snapshots: a bin's velocity is the mean over every particle that was in it
//! at any snapshot (particle-weighted), its stress and volume fraction the per-snapshot sums
//! averaged over the snapshots. From those [`CoarseFields`] derives what Ness's Figs. 3-8 draw:
//! the velocity gradients (central differences between bins; Fig. 4), the pressure, σ_xy and
//! N_1 (Fig. 6), the dissipation rate σ : γ̇ (Fig. 7) and the static zones (Fig. 5).
//!
//! Sign convention: stresses are compression positive, σ_ab = −(1/V) Σ r_a F_b as the engine's
//! `dipole_stress`; the Cauchy (tension positive) stress is −σᵀ, so the rate of working per
//! volume is S = −Σ_ab σ_ba ∂v_a/∂x_b, positive where the paste dissipates.

use crate::{AnalysisError, Result};
use ndarray::Array2;

/// One particle of a snapshot: centre (m), radius (m), velocity (m/s) and its share of the
/// force dipoles, total and hydrodynamic, component ab at index 3a + b (N m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub v: [f64; 3],
    pub w: [f64; 9],
    pub wh: [f64; 9],
}

/// A regular grid of square bins in the x-y plane, `depth` deep in z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinGrid {
    /// Lower-left corner of bin (0, 0) (m).
    pub x0: f64,
    pub y0: f64,
    /// Bin side (m).
    pub size: f64,
    pub nx: usize,
    pub ny: usize,
    /// Depth in z (m): the periodic slab's, or a monolayer's thickness.
    pub depth: f64,
    /// A monolayer (every centre in one plane, no force along z): the pressure is the
    /// in-plane mean (σ_xx + σ_yy)/2, σ_zz being zero there ([`Self::in_plane`]).
    pub planar: bool,
}

impl BinGrid {
    /// The grid of `size` bins covering [x0, x1] × [y0, y1] (rounded up to whole bins).
    pub fn covering(x: [f64; 2], y: [f64; 2], size: f64, depth: f64) -> Result<Self> {
        let ok = |v: f64| v.is_finite();
        if !(size > 0.0 && ok(size) && depth > 0.0 && ok(depth)) {
            return Err(AnalysisError::invalid(
                "bin size and depth",
                format!("{size}, {depth}"),
                "both must be positive and finite",
            ));
        }
        if !(x[1] > x[0] && y[1] > y[0] && x.iter().chain(&y).all(|&v| ok(v))) {
            return Err(AnalysisError::invalid(
                "bin grid extent",
                format!("x {x:?}, y {y:?}"),
                "needs finite, increasing bounds",
            ));
        }
        let n = |a: f64, b: f64| ((b - a) / size - 1e-9).ceil().max(1.0) as usize;
        Ok(Self {
            x0: x[0],
            y0: y[0],
            size,
            nx: n(x[0], x[1]),
            ny: n(y[0], y[1]),
            depth,
            planar: false,
        })
    }

    /// The same grid for a monolayer (2D pressure; see `planar`).
    pub fn in_plane(self, planar: bool) -> Self {
        Self { planar, ..self }
    }

    /// The mean normal stress of components xx, yy, zz: tr/3 in 3D, (xx + yy)/2 in a monolayer.
    fn mean_normal(&self, s: &[Array2<f64>; 9]) -> Array2<f64> {
        if self.planar {
            (&s[0] + &s[4]) / 2.0
        } else {
            (&s[0] + &s[4] + &s[8]) / 3.0
        }
    }

    pub fn volume(&self) -> f64 {
        self.size * self.size * self.depth
    }

    /// Bin (ix, iy) holding (x, y), if any.
    pub fn bin(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let fx = ((x - self.x0) / self.size).floor();
        let fy = ((y - self.y0) / self.size).floor();
        (fx >= 0.0 && fy >= 0.0 && (fx as usize) < self.nx && (fy as usize) < self.ny)
            .then_some((fx as usize, fy as usize))
    }

    /// Centre of bin (ix, iy) (m).
    pub fn centre(&self, ix: usize, iy: usize) -> (f64, f64) {
        (
            self.x0 + (ix as f64 + 0.5) * self.size,
            self.y0 + (iy as f64 + 0.5) * self.size,
        )
    }
}

/// Running sums over snapshots.
#[derive(Clone, Debug)]
pub struct BinSums {
    pub grid: BinGrid,
    snapshots: usize,
    count: Array2<f64>,
    volume: Array2<f64>,
    vel: Array2<[f64; 3]>,
    /// Σ V_p v and Σ V_p v_a v_b (grain volume times velocity): the kinetic stress.
    vol_v: Array2<[f64; 3]>,
    vol_vv: Array2<[f64; 9]>,
    w: Array2<[f64; 9]>,
    wh: Array2<[f64; 9]>,
}

impl BinSums {
    pub fn new(grid: BinGrid) -> Self {
        let sh = (grid.ny, grid.nx);
        Self {
            grid,
            snapshots: 0,
            count: Array2::zeros(sh),
            volume: Array2::zeros(sh),
            vel: Array2::from_elem(sh, [0.0; 3]),
            vol_v: Array2::from_elem(sh, [0.0; 3]),
            vol_vv: Array2::from_elem(sh, [0.0; 9]),
            w: Array2::from_elem(sh, [0.0; 9]),
            wh: Array2::from_elem(sh, [0.0; 9]),
        }
    }

    /// Add one snapshot's particles (those whose centre is outside the grid are left out).
    /// A non-finite dipole share is refused: the snapshot was taken without recorded forces.
    pub fn add_snapshot(&mut self, particles: &[Particle]) -> Result<()> {
        if let Some(p) = particles
            .iter()
            .find(|p| !p.w.iter().chain(&p.wh).chain(&p.v).all(|v| v.is_finite()))
        {
            return Err(AnalysisError::invalid(
                "particle dipole or velocity",
                format!("({}, {})", p.x, p.y),
                "is not finite: the snapshot carries no recorded forces (take it after a step)",
            ));
        }
        for p in particles {
            let Some((ix, iy)) = self.grid.bin(p.x, p.y) else {
                continue;
            };
            let k = [iy, ix];
            self.count[k] += 1.0;
            let vp = 4.0 / 3.0 * std::f64::consts::PI * p.r.powi(3);
            self.volume[k] += vp;
            for a in 0..3 {
                self.vol_v[k][a] += vp * p.v[a];
                for b in 0..3 {
                    self.vol_vv[k][3 * a + b] += vp * p.v[a] * p.v[b];
                }
            }
            for (a, b) in self.vel[k].iter_mut().zip(p.v) {
                *a += b;
            }
            for (a, b) in self.w[k].iter_mut().zip(p.w) {
                *a += b;
            }
            for (a, b) in self.wh[k].iter_mut().zip(p.wh) {
                *a += b;
            }
        }
        self.snapshots += 1;
        Ok(())
    }

    pub fn snapshots(&self) -> usize {
        self.snapshots
    }

    /// The time-averaged fields, the grains of density `density` (kg/m³, for the kinetic
    /// stress); `None` before any snapshot.
    pub fn fields(&self, density: f64) -> Option<CoarseFields> {
        if self.snapshots == 0 {
            return None;
        }
        let s = self.snapshots as f64;
        let vb = self.grid.volume();
        let occupied = |k: [usize; 2]| self.count[k] > 0.0;
        let sh = (self.grid.ny, self.grid.nx);
        let mut f = CoarseFields {
            grid: self.grid,
            snapshots: self.snapshots,
            count: self.count.mapv(|c| c / s),
            phi: self.volume.mapv(|v| v / (s * vb)),
            vel: [(); 3].map(|_| Array2::from_elem(sh, f64::NAN)),
            sigma: [(); 9].map(|_| Array2::zeros(sh)),
            sigma_hydro: [(); 9].map(|_| Array2::zeros(sh)),
            sigma_kinetic: [(); 9].map(|_| Array2::from_elem(sh, f64::NAN)),
        };
        for iy in 0..sh.0 {
            for ix in 0..sh.1 {
                let k = [iy, ix];
                if occupied(k) {
                    for a in 0..3 {
                        f.vel[a][k] = self.vel[k][a] / self.count[k];
                    }
                }
                if occupied(k) {
                    // Σ m v'_a v'_b about the bin's mass-weighted mean: Σ m v v − (Σ m v)(Σ m v)/Σ m.
                    let (m, mv, mvv) = (self.volume[k], self.vol_v[k], self.vol_vv[k]);
                    for a in 0..3 {
                        for b in 0..3 {
                            let c = 3 * a + b;
                            f.sigma_kinetic[c][k] = density * (mvv[c] - mv[a] * mv[b] / m) / (s * vb);
                        }
                    }
                }
                for c in 0..9 {
                    (f.sigma[c][k], f.sigma_hydro[c][k]) = if occupied(k) {
                        (self.w[k][c] / (s * vb), self.wh[k][c] / (s * vb))
                    } else {
                        (f64::NAN, f64::NAN)
                    };
                }
            }
        }
        Some(f)
    }
}

/// Time-averaged bin fields, arrays indexed [iy, ix] (row 0 at the grid's lowest y).
#[derive(Clone, Debug)]
pub struct CoarseFields {
    pub grid: BinGrid,
    pub snapshots: usize,
    /// Mean number of particle centres in the bin per snapshot.
    pub count: Array2<f64>,
    /// Volume fraction: the volume of the particles whose centre is in the bin over the bin's
    /// (Ness's definition; it exceeds the local solid fraction where centres crowd).
    pub phi: Array2<f64>,
    /// Mean velocity (m/s), NaN where no particle was.
    pub vel: [Array2<f64>; 3],
    /// Stress σ_ab at index 3a + b (Pa, compression positive), total and hydrodynamic part;
    /// NaN where no particle was.
    pub sigma: [Array2<f64>; 9],
    pub sigma_hydro: [Array2<f64>; 9],
    /// The kinetic (streaming) stress (1/V) Σ m v'_a v'_b about the bin's time-averaged mean
    /// velocity (Pa, positive like a pressure in this convention), which Eq. 7 leaves out
    /// (Ness: inertia negligible at St ≪ 1); NaN where no particle was.
    pub sigma_kinetic: [Array2<f64>; 9],
}

/// Velocity gradient of the x-y plane, ∂v_a/∂x_b at [a][b] (1/s).
pub type Gradient = [[Array2<f64>; 2]; 2];

impl CoarseFields {
    /// Speed |V| (m/s).
    pub fn speed(&self) -> Array2<f64> {
        let mut s = self.vel[0].clone();
        ndarray::Zip::from(&mut s)
            .and(&self.vel[1])
            .and(&self.vel[2])
            .for_each(|s, &y, &z| *s = (*s * *s + y * y + z * z).sqrt());
        s
    }

    /// The kinetic pressure tr σ_kinetic / 3 ((xx + yy)/2 in a monolayer).
    pub fn kinetic_pressure(&self) -> Array2<f64> {
        self.grid.mean_normal(&self.sigma_kinetic)
    }

    /// P = (σ_xx + σ_yy + σ_zz)/3 of the total stress, or of its hydrodynamic part; in a
    /// monolayer (σ_xx + σ_yy)/2, the 2D pressure.
    pub fn pressure(&self, hydro: bool) -> Array2<f64> {
        self.grid
            .mean_normal(if hydro { &self.sigma_hydro } else { &self.sigma })
    }

    /// First normal stress difference N_1 = σ_xx − σ_yy.
    pub fn n1(&self) -> Array2<f64> {
        &self.sigma[0] - &self.sigma[4]
    }

    /// ∂v_a/∂x_b for a, b ∈ {x, y} by central differences between neighbouring occupied bins,
    /// one-sided where a neighbour is empty or off the grid, NaN where both are (Ness Fig. 4;
    /// the ∂/∂z terms vanish on the periodic slab's average).
    pub fn gradient(&self) -> Gradient {
        let (ny, nx) = (self.grid.ny, self.grid.nx);
        let h = self.grid.size;
        let mut g: Gradient = [(); 2].map(|_| [(); 2].map(|_| Array2::from_elem((ny, nx), f64::NAN)));
        for (a, ga) in g.iter_mut().enumerate() {
            let v = &self.vel[a];
            let at = |iy: isize, ix: isize| -> Option<f64> {
                (iy >= 0 && ix >= 0 && (iy as usize) < ny && (ix as usize) < nx)
                    .then(|| v[[iy as usize, ix as usize]])
                    .filter(|x| x.is_finite())
            };
            for iy in 0..ny as isize {
                for ix in 0..nx as isize {
                    let Some(c) = at(iy, ix) else { continue };
                    for (b, (dy, dx)) in [(0isize, 1isize), (1, 0)].into_iter().enumerate() {
                        let (lo, hi) = (at(iy - dy, ix - dx), at(iy + dy, ix + dx));
                        ga[b][[iy as usize, ix as usize]] = match (lo, hi) {
                            (Some(l), Some(u)) => (u - l) / (2.0 * h),
                            (None, Some(u)) => (u - c) / h,
                            (Some(l), None) => (c - l) / h,
                            (None, None) => f64::NAN,
                        };
                    }
                }
            }
        }
        g
    }

    /// Rate of working per volume, S = −Σ_ab σ_ba ∂v_a/∂x_b over a, b ∈ {x, y} (W/m³; Ness
    /// Fig. 7's σ : γ̇ in the compression-positive convention: positive where energy is
    /// dissipated).
    pub fn dissipation(&self, g: &Gradient) -> Array2<f64> {
        let (ny, nx) = (self.grid.ny, self.grid.nx);
        let mut s = Array2::zeros((ny, nx));
        for (a, ga) in g.iter().enumerate() {
            for (b, gab) in ga.iter().enumerate() {
                s = s - &self.sigma[3 * b + a] * gab;
            }
        }
        s
    }

    /// Bins whose centre lies in `x` × `y` (m).
    fn bins_in(&self, x: [f64; 2], y: [f64; 2]) -> impl Iterator<Item = [usize; 2]> + '_ {
        let g = self.grid;
        (0..g.ny).flat_map(move |iy| {
            (0..g.nx).filter_map(move |ix| {
                let (cx, cy) = g.centre(ix, iy);
                (cx >= x[0] && cx <= x[1] && cy >= y[0] && cy <= y[1]).then_some([iy, ix])
            })
        })
    }

    /// Mean of `field` over the occupied bins whose centre lies in `x` × `y`, and how many.
    pub fn mean_over(&self, field: &Array2<f64>, x: [f64; 2], y: [f64; 2]) -> (f64, usize) {
        let (mut s, mut n) = (0.0, 0usize);
        for k in self.bins_in(x, y) {
            if self.count[k] > 0.0 && field[k].is_finite() {
                s += field[k];
                n += 1;
            }
        }
        (if n > 0 { s / n as f64 } else { f64::NAN }, n)
    }

    /// Volume flux along x per depth, ∫ φ v_x dy (m²/s), averaged over the grid's columns whose
    /// centre lies in `x` (m): at steady state the same at every x of the channel.
    pub fn flux_x(&self, x: [f64; 2]) -> f64 {
        let g = self.grid;
        let (mut s, mut n) = (0.0, 0usize);
        for ix in 0..g.nx {
            let cx = g.centre(ix, 0).0;
            if cx < x[0] || cx > x[1] {
                continue;
            }
            let col: f64 = (0..g.ny)
                .filter(|&iy| self.count[[iy, ix]] > 0.0)
                .map(|iy| self.phi[[iy, ix]] * self.vel[0][[iy, ix]] * g.size)
                .sum();
            s += col;
            n += 1;
        }
        if n > 0 { s / n as f64 } else { f64::NAN }
    }

    /// Static zone (Ness Fig. 5): the bins in `x` × `y` with |V| < `fraction` × `v_ref`, and the
    /// mean number of particles in them per snapshot.
    pub fn static_zone(&self, v_ref: f64, fraction: f64, x: [f64; 2], y: [f64; 2]) -> (Array2<bool>, f64) {
        let speed = self.speed();
        let mut zone = Array2::from_elem(speed.dim(), false);
        let mut grains = 0.0;
        for k in self.bins_in(x, y) {
            if self.count[k] > 0.0 && speed[k] < fraction * v_ref {
                zone[k] = true;
                grains += self.count[k];
            }
        }
        (zone, grains)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Particles on a regular lattice of spacing `h`/2 (four per bin, symmetric about each bin's
    /// centre), moving with `v(x, y)` and carrying `w(x, y)`.
    fn lattice(
        grid: &BinGrid,
        v: impl Fn(f64, f64) -> [f64; 3],
        w: impl Fn(f64, f64) -> [f64; 9],
    ) -> Vec<Particle> {
        let mut out = Vec::new();
        let q = grid.size / 4.0;
        for iy in 0..grid.ny {
            for ix in 0..grid.nx {
                let (cx, cy) = grid.centre(ix, iy);
                for (dx, dy) in [(-q, -q), (q, -q), (-q, q), (q, q)] {
                    let (x, y) = (cx + dx, cy + dy);
                    out.push(Particle {
                        x,
                        y,
                        r: 0.1 * grid.size,
                        v: v(x, y),
                        w: w(x, y),
                        wh: [0.0; 9],
                    });
                }
            }
        }
        out
    }

    fn grid() -> BinGrid {
        BinGrid::covering([0.0, 10e-5], [-4e-5, 4e-5], 1e-5, 5e-5).unwrap()
    }

    /// A linear velocity field v = (γ̇ y + e x, −e y, 0): every bin's central (and one-sided)
    /// difference of a linear field is exact, so the gradient is (e, γ̇; 0, −e) everywhere.
    #[test]
    fn gradient_of_a_linear_field_is_exact() {
        let g = grid();
        let (rate, ext) = (300.0, 120.0);
        let p = lattice(&g, |x, y| [rate * y + ext * x, -ext * y, 0.0], |_, _| [0.0; 9]);
        let mut sums = BinSums::new(g);
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(1000.0).unwrap();
        let gr = f.gradient();
        let want = [[ext, rate], [0.0, -ext]];
        for a in 0..2 {
            for b in 0..2 {
                for v in gr[a][b].iter() {
                    // Measured: 3e-13 relative to the largest rate (positions rounded).
                    assert!((v - want[a][b]).abs() < 1e-10 * rate, "{a}{b}: {v}");
                }
            }
        }
        assert_eq!(f.count.iter().copied().fold(0.0, f64::max), 4.0);
    }

    /// Dipole shares summed per bin over the bin volume, averaged over snapshots; a Newtonian
    /// stress σ = −2η D (compression positive) in simple shear dissipates S = η γ̇², and with
    /// σ_xy ≠ σ_yx only σ_yx (force along x on a plane normal to y, with ∂v_x/∂y) works.
    #[test]
    fn stress_is_the_binned_dipole_sum_and_dissipates_as_a_newtonian_fluid() {
        let g = grid();
        let (eta, rate) = (0.7, 250.0);
        // Each of the 4 particles of a bin carries a quarter of V_bin σ.
        let q = g.volume() / 4.0;
        let tau = -eta * rate; // σ_xy = σ_yx = −η γ̇ (compression positive)
        let p = lattice(
            &g,
            |_, y| [rate * y, 0.0, 0.0],
            |_, _| [2.0 * q, tau * q, 0.0, tau * q, 2.0 * q, 0.0, 0.0, 0.0, 2.0 * q],
        );
        let mut sums = BinSums::new(g);
        // Two snapshots of the same state average to it.
        sums.add_snapshot(&p).unwrap();
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(1000.0).unwrap();
        let pressure = f.pressure(false);
        let s = f.dissipation(&f.gradient());
        for k in [[0, 0], [3, 4], [7, 9]] {
            assert!((pressure[k] - 2.0).abs() < 1e-12, "{}", pressure[k]);
            assert!((f.sigma[1][k] - tau).abs() < 1e-9 * tau.abs());
            // S = −(σ_yx ∂v_x/∂y) = η γ̇².
            assert!(
                (s[k] - eta * rate * rate).abs() < 1e-9 * eta * rate * rate,
                "{}",
                s[k]
            );
        }
        assert_eq!(f.n1()[[2, 2]], 0.0);
        // An asymmetric stress: σ_xy = 3 τ, σ_yx = τ. S = −σ_yx γ̇ = η γ̇² still.
        let p = lattice(
            &g,
            |_, y| [rate * y, 0.0, 0.0],
            |_, _| {
                [
                    2.0 * q,
                    3.0 * tau * q,
                    0.0,
                    tau * q,
                    2.0 * q,
                    0.0,
                    0.0,
                    0.0,
                    2.0 * q,
                ]
            },
        );
        let mut sums = BinSums::new(g);
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(1000.0).unwrap();
        let s = f.dissipation(&f.gradient());
        assert!(
            (s[[3, 4]] - eta * rate * rate).abs() < 1e-9 * eta * rate * rate,
            "{}",
            s[[3, 4]]
        );
        // φ: four spheres of radius size/10 per bin.
        let phi = 4.0 * 4.0 / 3.0 * std::f64::consts::PI * (1e-6f64).powi(3) / g.volume();
        assert!((f.phi[[1, 1]] - phi).abs() < 1e-12 * phi);
    }

    /// A uniform flow: the flux is φ v_x times the grid's width at every x.
    #[test]
    fn flux_of_a_uniform_flow_is_phi_v_w() {
        let g = grid();
        let p = lattice(&g, |_, _| [2.0, 0.0, 0.0], |_, _| [0.0; 9]);
        let mut sums = BinSums::new(g);
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(1000.0).unwrap();
        let want = f.phi[[0, 0]] * 2.0 * 8e-5;
        for x in [[0.0, 1e-5], [2e-5, 9e-5]] {
            assert!((f.flux_x(x) - want).abs() < 1e-12 * want, "{}", f.flux_x(x));
        }
        assert!(f.flux_x([1.0, 2.0]).is_nan());
    }

    /// Velocities ±δ about a mean U alternating within each bin: the kinetic stress is
    /// ρ V_p Σ δ_a δ_b / V_bin, whatever U (fluctuations about the bin mean only).
    #[test]
    fn kinetic_stress_is_the_fluctuation_about_the_bin_mean() {
        let g = grid();
        let (u, d) = (3.0, 0.5);
        let mut p = lattice(&g, |_, _| [u, 0.0, 0.0], |_, _| [0.0; 9]);
        for (k, q) in p.iter_mut().enumerate() {
            let sgn = if k % 2 == 0 { 1.0 } else { -1.0 };
            q.v = [u + sgn * d, sgn * d, 0.0];
        }
        let mut sums = BinSums::new(g);
        sums.add_snapshot(&p).unwrap();
        let rho = 2500.0;
        let f = sums.fields(rho).unwrap();
        let vp = 4.0 / 3.0 * std::f64::consts::PI * (1e-6f64).powi(3);
        let want = rho * 4.0 * vp * d * d / g.volume();
        for c in [0, 1, 3, 4] {
            // xx, xy, yx, yy all ρ V_p Σ δ² / V (δ_x = δ_y = ±δ together).
            assert!(
                (f.sigma_kinetic[c][[2, 3]] - want).abs() < 1e-9 * want,
                "{c}: {}",
                f.sigma_kinetic[c][[2, 3]]
            );
        }
        assert!(f.sigma_kinetic[8][[2, 3]].abs() < 1e-12 * want);
        assert!((f.kinetic_pressure()[[2, 3]] - 2.0 * want / 3.0).abs() < 1e-9 * want);
        // A monolayer's pressure is the in-plane mean: the same motion gives (xx + yy)/2 = want.
        let mut sums = BinSums::new(g.in_plane(true));
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(rho).unwrap();
        assert!((f.kinetic_pressure()[[2, 3]] - want).abs() < 1e-9 * want);
    }

    #[test]
    fn static_zone_counts_the_slow_bins_in_its_window() {
        let g = grid();
        // Speed rises with x (bin means 0.5, 1.5, 2.5, ... m/s): a quarter of 8 m/s keeps two columns.
        let p = lattice(&g, |x, _| [1e5 * x, 0.0, 0.0], |_, _| [0.0; 9]);
        let mut sums = BinSums::new(g);
        sums.add_snapshot(&p).unwrap();
        let f = sums.fields(1000.0).unwrap();
        let (zone, grains) = f.static_zone(8.0, 0.25, [0.0, 1.0], [0.0, 1.0]);
        // Two columns in the 4 rows with y-centre ≥ 0: 8 bins of 4 particles.
        assert_eq!(zone.iter().filter(|&&z| z).count(), 8);
        assert_eq!(grains, 32.0);
    }

    #[test]
    fn snapshots_without_recorded_forces_are_refused() {
        let g = grid();
        let mut p = lattice(&g, |_, _| [0.0; 3], |_, _| [0.0; 9]);
        p[3].w[4] = f64::NAN;
        assert!(BinSums::new(g).add_snapshot(&p).is_err());
        assert!(BinGrid::covering([0.0, 1.0], [0.0, 1.0], 0.0, 1.0).is_err());
        assert!(BinGrid::covering([1.0, 0.0], [0.0, 1.0], 0.1, 1.0).is_err());
    }
}
