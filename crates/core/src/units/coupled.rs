//! SI <-> lattice units of a coupled run: the LBM units of [`super::lattice`] (Su
//! Eqs. 15-16) plus the DEM time step and the integer LBM-DEM time-step ratio of Su et al.
//! 2020 Table 3 (r = δt / Δt DEM cycles per LBM cycle). `lbdem_coupling::units` re-exports it.

use super::lattice::{LatticeUnits, UnitsError};

/// How positions, velocities and loads convert between the DEM (SI, 2D per metre of depth)
/// and the lattice. The lattice node (i, j) has its centre at `origin + (i + ½, j + ½) dx`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CouplingUnits {
    pub lattice: LatticeUnits,
    pub origin: [f64; 2],
    /// DEM time step (s).
    pub dt_dem: f64,
    /// DEM sub-steps per LBM step.
    pub ratio: u32,
}

impl CouplingUnits {
    /// Check that `lattice.dt / dt_dem` is a whole number (to 1e-9 relative) of at least 1.
    pub fn new(lattice: LatticeUnits, origin: [f64; 2], dt_dem: f64) -> Result<Self, UnitsError> {
        let r = lattice.dt / dt_dem;
        let whole = r.round();
        if !(r.is_finite() && whole >= 1.0 && (r - whole).abs() <= 1e-9 * whole) {
            return Err(UnitsError::Ratio { ratio: r });
        }
        Ok(Self {
            lattice,
            origin,
            dt_dem,
            ratio: whole as u32,
        })
    }
    pub fn dx(&self) -> f64 {
        self.lattice.dx
    }
    pub fn dt(&self) -> f64 {
        self.lattice.dt
    }
    /// SI position -> lattice coordinates (cell (i, j) spans [i, i + 1] x [j, j + 1]).
    pub fn position_to_lattice(&self, p: [f64; 2]) -> [f64; 2] {
        [
            (p[0] - self.origin[0]) / self.dx(),
            (p[1] - self.origin[1]) / self.dx(),
        ]
    }
    pub fn length_to_lattice(&self, l: f64) -> f64 {
        l / self.dx()
    }
    pub fn velocity_to_lattice(&self, v: [f64; 2]) -> [f64; 2] {
        let s = self.dt() / self.dx();
        [v[0] * s, v[1] * s]
    }
    pub fn omega_to_lattice(&self, w: f64) -> f64 {
        w * self.dt()
    }
    /// Lattice force -> N per metre of depth (ρ dx³/dt²).
    pub fn force_to_si(&self, f: [f64; 2]) -> [f64; 2] {
        [
            self.lattice.force_to_si(f[0], 2),
            self.lattice.force_to_si(f[1], 2),
        ]
    }
    /// Lattice moment -> N m per metre of depth.
    pub fn torque_to_si(&self, t: f64) -> f64 {
        self.lattice.torque_to_si(t, 2)
    }
    /// Lattice momentum -> kg m/s per metre of depth (ρ dx³/dt).
    pub fn momentum_to_si(&self, j: [f64; 2]) -> [f64; 2] {
        let s = self.lattice.rho * self.dx().powi(3) / self.dt();
        [j[0] * s, j[1] * s]
    }
    /// Lattice pressure change (Δρ c_s²) -> Pa (Su Eq. 19).
    pub fn pressure_to_si(&self, p: f64) -> f64 {
        p * self.lattice.rho * self.dx() * self.dx() / (self.dt() * self.dt())
    }
}

/// Largest density change Δρ/ρ a scene may need the liquid to carry its grains' buoyant weight
/// ([`buoyant_load`] through [`LatticeUnits::pressure_to_density`]): above it a coupled scene is
/// refused before it starts. Found by running the full Float case of Su et al. 2020
/// (`scenes/su2020/float.toml`, docs/stability.md "The liquid's pressure load").
pub const LOAD_DENSITY_MAX: f64 = 0.5;

/// Smallest grain-to-liquid density ratio (with any mass scaling: the grains' inertia) a PSM
/// scene may have among the grains that feel the liquid. The coupling is explicit: the load of
/// one LBM step is held over the DEM sub-steps, and a grain lighter than the liquid its solid
/// term moves overshoots. Found by running the reduced Su shear cell from 0.23 to 3.6
/// (`sweeps/su2020-density-ratio.toml`, docs/stability.md "Near-neutral grains"): every run at
/// 0.45 and below blew up, every run at 0.56 and above finished. Su's cases sit at 0.90-0.97.
pub const PSM_DENSITY_RATIO_MIN: f64 = 0.5;

/// Grain-to-liquid density ratio under which a PSM scene is warned (above
/// [`PSM_DENSITY_RATIO_MIN`] it still runs): where the edge sits depends on the case. A disk
/// settling in open liquid (`lbdem interior-liquid-map`, docs/stability.md "Near-neutral grains")
/// blew up at 0.7 with 4 and 6 cells per diameter and at 0.8 with 10 (τ 0.8 and 1), and ran at
/// 0.9 at every resolution; the shear cell above ran from 0.56.
pub const PSM_DENSITY_RATIO_WARN: f64 = 0.85;

/// The pressure difference (Pa) the liquid must carry when the grains move through it as one
/// packing: their buoyant weight over the box's width, Δp = Σ m_i |a| / (W d), with `mass` the
/// grains' total mass (kg, over the sample depth `depth`, m), `accel` the net acceleration the DEM
/// gives them (gravity × the buoyancy factor 1 − ρ_L/ρ_S, m/s²), and W the box's extent across
/// `accel` (`size` = the box's sides, m). For a packing of solid fraction φ and height H this is
/// |ρ_S − ρ_L| g φ H, the pressure difference that drives the liquid's counter-flow through it.
pub fn buoyant_load(mass: f64, accel: [f64; 2], size: [f64; 2], depth: f64) -> f64 {
    let a = accel[0].hypot(accel[1]);
    if a == 0.0 {
        return 0.0;
    }
    // the box's extent along the acceleration, and so its width across it
    let along = (accel[0].abs() * size[0] + accel[1].abs() * size[1]) / a;
    let width = size[0] * size[1] / along;
    mass * a / (width * depth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::lattice::{LatticeInput, TimeSpec};

    fn lattice(dt: f64) -> LatticeUnits {
        // Su et al. 2020 Table 3, 30 µm/s runs: dx = 40 µm, δt = 6.66e-4 s, ν ≈ 6e-7 m²/s.
        LatticeUnits::derive(&LatticeInput::new(40e-6, 6.0e-7, 2700.0, 1e-3, TimeSpec::Dt(dt))).unwrap()
    }

    #[test]
    fn ratio_must_be_whole() {
        let u = CouplingUnits::new(lattice(6.66e-4), [0.0; 2], 6.66e-6).unwrap();
        assert_eq!(u.ratio, 100);
        let e = CouplingUnits::new(lattice(6.66e-4), [0.0; 2], 7e-6).unwrap_err();
        assert!(e.to_string().contains("95.14"), "{e}");
        assert!(CouplingUnits::new(lattice(6.66e-4), [0.0; 2], 1e-3).is_err());
    }

    #[test]
    fn momentum_and_impulse_agree() {
        // An LBM step moves lattice momentum j; the grains receive F dt_lbm: same SI figure.
        let u = CouplingUnits::new(lattice(6.66e-4), [1.0, 2.0], 6.66e-6).unwrap();
        let j = [0.3, -0.2];
        let f = u.force_to_si(j);
        let p = u.momentum_to_si(j);
        for a in 0..2 {
            let rel = (f[a] * u.dt() - p[a]).abs() / p[a].abs();
            assert!(rel <= 1e-14, "{rel}");
        }
        let p = u.position_to_lattice([1.0 + 40e-6, 2.0]);
        assert!((p[0] - 1.0).abs() <= 1e-9, "{}", p[0]);
        assert_eq!(p[1], 0.0);
    }

    #[test]
    fn buoyant_load_of_the_float_packing() {
        // Su et al. 2020 Float: ρ_S = 2634, ρ_L = 2856 kg/m³, a 5 mm packing at φ = 0.7 in a
        // 10 mm box, 0.2 mm deep: |ρ_S − ρ_L| g φ H = 222 × 9.81 × 0.7 × 5e-3 = 7.62 Pa.
        let (w, h, d, phi) = (0.010, 0.005, 2e-4, 0.7);
        let mass = 2634.0 * phi * w * h * d;
        let a = 9.81 * (1.0 - 2856.0 / 2634.0);
        let p = buoyant_load(mass, [0.0, -a], [w, h], d);
        assert!((p - 222.0 * 9.81 * phi * h).abs() < 1e-9, "{p}");
        // the same along x: the width is then the box's height
        assert!((buoyant_load(mass, [a, 0.0], [h, w], d) - p).abs() < 1e-9);
        assert_eq!(buoyant_load(mass, [0.0, 0.0], [w, h], d), 0.0);
        // Table 3's step: pressure unit ρ_L (dx/δt)² = 10.3 Pa, Δρ/ρ = Δp/(c_s² 10.3) ≈ 2.2
        let inp = |dt| LatticeInput::new(4e-5, 1.82e-3 / 2856.0, 2856.0, 2e-3, TimeSpec::Dt(dt));
        let drho = |dt| LatticeUnits::derive(&inp(dt)).unwrap().pressure_to_density(p);
        assert!((drho(6.66e-4) - 2.22).abs() < 0.01, "{}", drho(6.66e-4));
        assert!(drho(6.66e-4) > LOAD_DENSITY_MAX && drho(1.332e-4) < LOAD_DENSITY_MAX);
    }
}
