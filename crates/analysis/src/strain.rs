//! Strain by triangulation (Su et al. 2020 Sect. 2.5; the constant-strain triangle of refs.
//! [104-106]): within each triangle the displacement is linear, u(X) = u₁ + H (X − X₁), so the
//! three corner displacements fix the 2 × 2 displacement gradient H = ∂u/∂X exactly:
//!
//! ```text
//! H = [u₂ − u₁, u₃ − u₁] · [X₂ − X₁, X₃ − X₁]⁻¹        (columns are edge vectors)
//! ε_xx = H_xx,  ε_yy = H_yy,  ε_xy = ½ γ_xy = ½ (H_xy + H_yx),  ω = ½ (H_yx − H_xy)
//! ```
//!
//! Su take ε_xx + ε_yy as the volumetric strain of a triangle and ε_xy = ½γ_xy as its shear
//! strain (the small-strain measures). The triangle's area ratio J = det(I + H) is kept as well:
//! J − 1 is what Eq. 5 measures from intensity and ln J is Eq. 18 (see [`crate::volume`]).
//!
//! For any affine motion u = H₀ X + c every triangle returns H₀ to round-off, and the
//! area-weighted mean of H over the mesh equals the boundary integral (1/A)∮ u ⊗ n ds of the
//! piecewise-linear field, whatever the motion inside.

use crate::mesh::Mesh;
use crate::{AnalysisError, P2, Result};
use nalgebra::Matrix2;
use rayon::prelude::*;
use serde::Serialize;

/// The strain of one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TriangleStrain {
    /// Displacement gradient ∂u_i/∂X_j, row-major: [[H_xx, H_xy], [H_yx, H_yy]].
    pub h: [[f64; 2]; 2],
}

impl TriangleStrain {
    pub fn eps_xx(&self) -> f64 {
        self.h[0][0]
    }
    pub fn eps_yy(&self) -> f64 {
        self.h[1][1]
    }
    /// ε_xy = ½ γ_xy (Su: "ε_xy was approximated as 0.5 γ_xy").
    pub fn eps_xy(&self) -> f64 {
        0.5 * (self.h[0][1] + self.h[1][0])
    }
    /// Small-strain volumetric strain ε_xx + ε_yy (Su Figs. 6, 8, 11: "TRI").
    pub fn eps_vol(&self) -> f64 {
        self.h[0][0] + self.h[1][1]
    }
    /// Rigid rotation ω = ½ (∂u_y/∂x − ∂u_x/∂y), counter-clockwise positive (rad, small).
    pub fn rotation(&self) -> f64 {
        0.5 * (self.h[1][0] - self.h[0][1])
    }
    /// Area ratio J = det(I + H) = A_deformed / A_reference.
    pub fn area_ratio(&self) -> f64 {
        (1.0 + self.h[0][0]) * (1.0 + self.h[1][1]) - self.h[0][1] * self.h[1][0]
    }
}

/// The displacement gradient of the triangle with reference corners `x` and displaced corners
/// `y` (exact for a linear field; `None` when the reference triangle is degenerate).
pub fn triangle_gradient(x: [P2; 3], y: [P2; 3]) -> Option<TriangleStrain> {
    let d = Matrix2::new(
        x[1][0] - x[0][0],
        x[2][0] - x[0][0],
        x[1][1] - x[0][1],
        x[2][1] - x[0][1],
    );
    let u = |k: usize, c: usize| (y[k][c] - x[k][c]) - (y[0][c] - x[0][c]);
    let du = Matrix2::new(u(1, 0), u(2, 0), u(1, 1), u(2, 1));
    let inv = d.try_inverse()?;
    let h = du * inv;
    Some(TriangleStrain {
        h: [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]],
    })
}

/// The strain of every triangle of `mesh` between the reference positions `reference` (the
/// mesh's vertices) and `deformed` (the same grains, same order, later).
pub fn triangle_strains(mesh: &Mesh, reference: &[P2], deformed: &[P2]) -> Result<Vec<TriangleStrain>> {
    if reference.len() != deformed.len() {
        return Err(AnalysisError::CountMismatch {
            what: "triangulation strain".into(),
            n_ref: reference.len(),
            n_def: deformed.len(),
        });
    }
    if let Some(i) = deformed
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(AnalysisError::invalid(
            &format!("deformed point {i}"),
            format!("({}, {})", deformed[i][0], deformed[i][1]),
            "is not finite; the snapshot holds a NaN position (a blown-up run?)",
        ));
    }
    mesh.triangles
        .par_iter()
        .map(|&[a, b, c]| {
            triangle_gradient(
                [reference[a], reference[b], reference[c]],
                [deformed[a], deformed[b], deformed[c]],
            )
            .ok_or_else(|| {
                AnalysisError::invalid(
                    "triangle",
                    format!("({a}, {b}, {c})"),
                    "has zero reference area; the mesh was not built from these reference points",
                )
            })
        })
        .collect()
}

/// Area-weighted mean displacement gradient over the mesh (reference areas): the mean strain
/// of the triangulated region.
pub fn mean_gradient(mesh: &Mesh, strains: &[TriangleStrain]) -> TriangleStrain {
    let mut h = [[0.0; 2]; 2];
    let mut a_sum = 0.0;
    for (s, &a) in strains.iter().zip(&mesh.area) {
        for (row, srow) in h.iter_mut().zip(&s.h) {
            for (v, sv) in row.iter_mut().zip(srow) {
                *v += a * sv;
            }
        }
        a_sum += a;
    }
    for row in &mut h {
        for v in row {
            *v /= a_sum;
        }
    }
    TriangleStrain { h }
}

/// Deformed over reference area of the whole mesh, Σ A_t J_t / Σ A_t: the area ratio of the
/// triangulated region, exact for any motion (no small-strain assumption).
pub fn mesh_area_ratio(mesh: &Mesh, strains: &[TriangleStrain]) -> f64 {
    let (num, den) = strains
        .iter()
        .zip(&mesh.area)
        .fold((0.0, 0.0), |(n, d), (s, &a)| (n + a * s.area_ratio(), d + a));
    num / den
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::signed_area;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Random scattered points in a 20 x 15 box, as grain centroids.
    fn cloud(n: usize, seed: u64) -> Vec<P2> {
        let mut r = Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n)
            .map(|_| [20.0 * r.random::<f64>(), 15.0 * r.random::<f64>()])
            .collect()
    }

    /// Grain-like centroids: a 24 x 18 lattice of spacing 0.8, each point shifted at random by
    /// up to 0.25 in x and y (no two grains closer than 0.3, as non-overlapping grains).
    fn grains(seed: u64) -> Vec<P2> {
        let mut r = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut v = Vec::new();
        for j in 0..18 {
            for i in 0..24 {
                let (a, b): (f64, f64) = (r.random(), r.random());
                v.push([0.8 * i as f64 + 0.5 * (a - 0.5), 0.8 * j as f64 + 0.5 * (b - 0.5)]);
            }
        }
        v
    }

    fn max_diff(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> f64 {
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    fn affine(p: &[P2], h: [[f64; 2]; 2], c: P2) -> Vec<P2> {
        p.iter()
            .map(|x| {
                [
                    x[0] + h[0][0] * x[0] + h[0][1] * x[1] + c[0],
                    x[1] + h[1][0] * x[0] + h[1][1] * x[1] + c[1],
                ]
            })
            .collect()
    }

    /// Every imposed affine motion comes back exactly: each triangle's H, its area ratio and
    /// the mesh's. Largest deviations measured: H 1.4e-13 (simple shear), a triangle's J 5.1e-14,
    /// the mesh's J 8.9e-16 (tolerances 3e-13, 1e-13, 2e-15). Displacements are differences of
    /// positions up to 20, whose ulps (3.6e-15) divided by edges down to 0.3 give that size.
    #[test]
    fn affine_motions_are_recovered_to_round_off() {
        let pts = grains(1);
        let mesh = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        let th: f64 = 0.3;
        let cases: [(&str, [[f64; 2]; 2]); 5] = [
            ("uniaxial", [[0.0, 0.0], [0.0, -0.08]]),
            ("simple shear", [[0.0, 0.2], [0.0, 0.0]]),
            (
                "rotation",
                [[th.cos() - 1.0, -th.sin()], [th.sin(), th.cos() - 1.0]],
            ),
            ("dilation", [[0.05, 0.0], [0.0, 0.05]]),
            ("general", [[0.03, -0.11], [0.07, -0.02]]),
        ];
        for (name, h0) in cases {
            let def = affine(&pts, h0, [0.37, -1.2]);
            let s = triangle_strains(&mesh, &pts, &def).unwrap();
            let j0 = (1.0 + h0[0][0]) * (1.0 + h0[1][1]) - h0[0][1] * h0[1][0];
            let (mut worst, mut worst_j) = (0.0f64, 0.0f64);
            for (t, st) in s.iter().enumerate() {
                worst = worst.max(max_diff(st.h, h0));
                // J is the ratio of the deformed to the reference triangle's area.
                let [a, b, c] = mesh.triangles[t];
                let jt = signed_area(def[a], def[b], def[c]) / mesh.area[t];
                worst_j = worst_j
                    .max((st.area_ratio() - jt).abs())
                    .max((st.area_ratio() - j0).abs());
            }
            assert!(worst_j < 1e-13, "{name}: J off by {worst_j:e}");
            assert!(worst < 3e-13, "{name}: H off by {worst:e}");
            let m = mean_gradient(&mesh, &s);
            assert!(max_diff(m.h, h0) < 3e-13, "{name}: mean H");
            assert!((mesh_area_ratio(&mesh, &s) - j0).abs() < 2e-15);
        }
        // What each case means for the strain measures (a rotation is not a strain: its small-
        // strain trace is 2 (cos θ - 1) while its area ratio stays 1).
        let rot = triangle_gradient(
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            affine(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], cases[2].1, [0.0, 0.0])
                .try_into()
                .unwrap(),
        )
        .unwrap();
        assert!((rot.area_ratio() - 1.0).abs() < 1e-15);
        assert!((rot.eps_vol() - 2.0 * (th.cos() - 1.0)).abs() < 1e-15);
        assert!((rot.rotation() - th.sin()).abs() < 1e-15 && rot.eps_xy().abs() < 1e-15);
        let shear = TriangleStrain { h: cases[1].1 };
        assert_eq!(
            (shear.eps_vol(), shear.eps_xy(), shear.rotation()),
            (0.0, 0.1, -0.1)
        );
    }

    /// A non-affine field with a known mean: the affine part H₀ plus random displacements of
    /// every point off the convex hull. The piecewise-linear field then agrees with H₀ X on the
    /// whole boundary, so its mean gradient is exactly H₀ (divergence theorem) while single
    /// triangles strain far from it. Measured: 6.2e-17 off (tolerance 2e-16); single triangles up to
    /// 8 off.
    #[test]
    fn non_affine_field_has_the_known_mean_strain() {
        let mut pts = cloud(600, 2);
        // A rectangular frame of hull points, so the boundary is known.
        for i in 0..=20 {
            pts.push([i as f64, 0.0]);
            pts.push([i as f64, 15.0]);
        }
        for j in 1..15 {
            pts.push([0.0, j as f64]);
            pts.push([20.0, j as f64]);
        }
        let mesh = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        let h0 = [[0.02, 0.05], [-0.01, -0.04]];
        let mut def = affine(&pts, h0, [0.0, 0.0]);
        let mut r = Xoshiro256PlusPlus::seed_from_u64(3);
        let on_frame = |p: P2| p[0] == 0.0 || p[0] == 20.0 || p[1] == 0.0 || p[1] == 15.0;
        for (d, p) in def.iter_mut().zip(&pts) {
            if !on_frame(*p) {
                d[0] += 0.15 * (r.random::<f64>() - 0.5);
                d[1] += 0.15 * (r.random::<f64>() - 0.5);
            }
        }
        let s = triangle_strains(&mesh, &pts, &def).unwrap();
        let spread = s
            .iter()
            .map(|t| (t.eps_vol() - (h0[0][0] + h0[1][1])).abs())
            .fold(0.0, f64::max);
        assert!(spread > 0.1, "the field is not far from affine ({spread})");
        let m = mean_gradient(&mesh, &s);
        assert!(max_diff(m.h, h0) < 2e-16, "{:?} vs {h0:?}", m.h);
        // The mesh's area ratio is that of the frame, which moved affinely.
        let j0 = (1.0 + h0[0][0]) * (1.0 + h0[1][1]) - h0[0][1] * h0[1][0];
        assert!((mesh_area_ratio(&mesh, &s) - j0).abs() < 1e-13);
    }

    #[test]
    fn mismatched_or_non_finite_snapshots_are_refused() {
        let pts = cloud(20, 4);
        let mesh = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        assert!(matches!(
            triangle_strains(&mesh, &pts, &pts[1..]),
            Err(AnalysisError::CountMismatch { .. })
        ));
        let mut bad = pts.clone();
        bad[3][1] = f64::NAN;
        let e = triangle_strains(&mesh, &pts, &bad).unwrap_err().to_string();
        assert!(e.contains("deformed point 3") && e.contains("NaN"), "{e}");
    }
}
