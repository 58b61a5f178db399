//! The packed zone of floating grains (Su et al. 2020 Sect. 3.2, Fig. 5h): the box is cut into
//! horizontal bands from the side the grains pack against; the zone is the run of bands from
//! that side whose grains are all slower than the threshold. Its packing fraction f_S,pk,PK is
//! the grains' area in it over its area; `packing_box` is the grains' area over the whole box
//! (f_S,pk,FOV).

use crate::scenes::schema::{PackedZoneSection, Scene};
use anyhow::{Result, bail};
use lbdem_dem::System;

pub const COLUMNS: [&str; 3] = ["packed_zone_fraction", "packed_zone_height", "packing_box"];

#[derive(Clone, Debug)]
pub struct PackedZone {
    top: bool,
    slower_than: f64,
    band: f64,
    lo: [f64; 2],
    hi: [f64; 2],
}

/// Area of the disc (centre height `yc`, radius `r`) between heights `y0` < `y1`.
fn disc_between(yc: f64, r: f64, y0: f64, y1: f64) -> f64 {
    // ∫ 2√(r² − h²) dh = h√(r² − h²) + r² asin(h/r)
    let f = |h: f64| {
        let h = h.clamp(-r, r);
        h * (r * r - h * h).max(0.0).sqrt() + r * r * (h / r).asin()
    };
    f(y1 - yc) - f(y0 - yc)
}

impl PackedZone {
    pub fn new(s: &Scene) -> Result<Option<Self>> {
        let Some(p) = &s.packed_zone else {
            return Ok(None);
        };
        Self::from_section(p, s.domain.lo2(), s.domain.hi2()).map(Some)
    }

    fn from_section(p: &PackedZoneSection, lo: [f64; 2], hi: [f64; 2]) -> Result<Self> {
        let top = match p.side.as_str() {
            "top" => true,
            "bottom" => false,
            other => bail!("[packed_zone] side = {other:?}: use \"top\" or \"bottom\""),
        };
        if !(p.band > 0.0 && p.band < hi[1] - lo[1]) {
            bail!(
                "[packed_zone] band = {}: give a height in m between 0 and the box height {}",
                p.band,
                hi[1] - lo[1]
            );
        }
        if !(p.slower_than > 0.0 && p.slower_than.is_finite()) {
            bail!(
                "[packed_zone] slower_than = {}: give a positive speed in m/s",
                p.slower_than
            );
        }
        Ok(Self {
            top,
            slower_than: p.slower_than,
            band: p.band,
            lo,
            hi,
        })
    }

    /// One series row ([`COLUMNS`]): a grain is still when its speed is below `slower_than`.
    pub fn sample(&self, sys: &System) -> Vec<f64> {
        let b = &sys.bodies;
        let grains = (0..b.len()).map(|k| {
            let speed = b.vel[k].x.hypot(b.vel[k].y);
            let circles =
                (b.circle_start[k]..b.circle_start[k + 1]).map(move |c| (b.circle_pos(c).y, b.circle_r[c]));
            (b.mass[k] / b.density[k], speed < self.slower_than, circles)
        });
        self.measure(grains).to_vec()
    }

    /// The zone of grains given as (own area, still, circles (y, r)): Su's radiographs call a
    /// grain still when it moved under 2 µm in 10 s (Sect. 3.2); a run's series uses the
    /// instantaneous speed ([`Self::sample`]), the analysis of its snapshots the displacement.
    /// Returns [`COLUMNS`]: the zone's packing fraction (NaN when no band is packed), its
    /// height and the grains' area over the box.
    pub fn measure<I, C>(&self, grains: I) -> [f64; 3]
    where
        I: Iterator<Item = (f64, bool, C)>,
        C: Iterator<Item = (f64, f64)> + Clone,
    {
        let (bands, total) = self.bands(grains);
        let [fraction, height] = self.zone(&bands);
        [fraction, height, total]
    }

    /// The zone's packing fraction (NaN when no band is packed) and height, from its bands.
    pub fn zone(&self, bands: &[Band]) -> [f64; 2] {
        let (area, height) = bands
            .iter()
            .take_while(|b| b.still)
            .fold((0.0, 0.0), |(a, h), b| (a + b.area, h + b.height));
        let width = self.hi[0] - self.lo[0];
        let fraction = if height > 0.0 {
            area / (height * width)
        } else {
            f64::NAN
        };
        [fraction, height]
    }

    /// The bands from the packing side with their packing fractions, and the grains' area over
    /// the box. A band is still when it holds grains and all of them are still; the zone is the
    /// run of still bands from the packing side ([`Self::measure`]).
    pub fn bands<I, C>(&self, grains: I) -> (Vec<Band>, f64)
    where
        I: Iterator<Item = (f64, bool, C)>,
        C: Iterator<Item = (f64, f64)> + Clone,
    {
        let height = self.hi[1] - self.lo[1];
        let width = self.hi[0] - self.lo[0];
        let n = (height / self.band).ceil() as usize;
        let mut area = vec![0.0; n];
        let mut moving = vec![false; n];
        // Band k counts from the packing side.
        let band_of = |y: f64| {
            let from = if self.top { self.hi[1] - y } else { y - self.lo[1] };
            ((from / self.band).floor().max(0.0) as usize).min(n - 1)
        };
        let bounds = |k: usize| {
            let (a, c) = (k as f64 * self.band, ((k + 1) as f64 * self.band).min(height));
            if self.top {
                (self.hi[1] - c, self.hi[1] - a)
            } else {
                (self.lo[1] + a, self.lo[1] + c)
            }
        };
        let mut total = 0.0;
        for (own, still, circles) in grains {
            // The circles of a clump overlap: scale their areas to the body's own.
            let sum: f64 = circles
                .clone()
                .map(|(_, r)| std::f64::consts::PI * r.powi(2))
                .sum();
            let scale = own / sum.max(f64::MIN_POSITIVE);
            total += own;
            for (y, r) in circles {
                let (k0, k1) = (band_of(y + r), band_of(y - r));
                for kb in k0.min(k1)..=k0.max(k1) {
                    let (y0, y1) = bounds(kb);
                    let a = disc_between(y, r, y0, y1) * scale;
                    if a > 0.0 {
                        area[kb] += a;
                        moving[kb] |= !still;
                    }
                }
            }
        }
        let bands = (0..n)
            .map(|kb| {
                let (y0, y1) = bounds(kb);
                Band {
                    depth: kb as f64 * self.band + 0.5 * (y1 - y0),
                    height: y1 - y0,
                    area: area[kb],
                    fraction: area[kb] / ((y1 - y0) * width),
                    still: area[kb] > 0.0 && !moving[kb],
                }
            })
            .collect();
        (bands, total / (width * height))
    }
}

/// One band of [`PackedZone::bands`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    /// Depth of the band's middle from the packing side (m).
    pub depth: f64,
    /// Its height (m; the last band of the box may be cut short).
    pub height: f64,
    /// The grains' area in it (m²).
    pub area: f64,
    /// The grains' area in it over its area.
    pub fraction: f64,
    /// It holds grains and all of them are still.
    pub still: bool,
}

/// The zone's packing fraction without its two edge bands, the one against the wall (a flat wall
/// orders the first layer) and the ragged lower one, which a band only partly covers: the
/// packing inside the layer, which does not depend on where a band edge falls (NaN with fewer
/// than three bands in the zone).
pub fn interior_fraction(bands: &[Band]) -> f64 {
    let zone = bands.iter().take_while(|b| b.still).count();
    if zone < 3 {
        return f64::NAN;
    }
    let inner = &bands[1..zone - 1];
    let (a, h) = inner
        .iter()
        .fold((0.0, 0.0), |(a, h), b| (a + b.fraction * b.height, h + b.height));
    a / h
}

#[cfg(test)]
mod tests {
    use super::*;
    use lbdem_dem::{Bodies, ClumpShape, Domain, Vec2};

    /// Rows of touching discs (r = 0.05 on a 0.1 grid) from the top of a 1 x 1 box down, disc i
    /// of row `row` kept where `keep(row, i)`, and the zone of 0.1 bands from the top.
    fn rows_of_discs(rows: usize, keep: impl Fn(usize, usize) -> bool) -> (Bodies, PackedZone) {
        let mut b = Bodies::new();
        let disc = ClumpShape::disk(0.05);
        for row in 0..rows {
            for i in (0..10).filter(|&i| keep(row, i)) {
                b.add(
                    &disc,
                    1.0,
                    Vec2::new(0.05 + 0.1 * i as f64, 0.95 - 0.1 * row as f64),
                    0.0,
                )
                .expect("valid disc");
            }
        }
        let pz = PackedZone {
            top: true,
            slower_than: 0.1,
            band: 0.1,
            lo: [0.0, 0.0],
            hi: [1.0, 1.0],
        };
        (b, pz)
    }

    #[test]
    fn a_slow_layer_on_top_is_the_zone_and_its_fraction_is_exact() {
        // Two rows of touching discs fill the top 0.2 of the box: fraction π/4 in a zone 0.2
        // high; a fast disc below stops the zone there. The body's area comes from its mass
        // properties: 3.3e-10 relative off π r² (measured).
        let (mut b, pz) = rows_of_discs(2, |_, _| true);
        let disc = ClumpShape::disk(0.05);
        let fast = b.add(&disc, 1.0, Vec2::new(0.5, 0.75), 0.0).expect("valid disc");
        b.vel[fast] = Vec2::new(0.0, 1.0);
        let sys = System::new(b, Domain::open(Vec2::ZERO, Vec2::new(1.0, 1.0)));
        let v = pz.sample(&sys);
        assert!((v[0] - std::f64::consts::FRAC_PI_4).abs() < 7e-10, "{v:?}");
        assert!((v[1] - 0.2).abs() < 1e-12);
        assert!(
            (v[2] / (21.0 * std::f64::consts::PI * 0.0025) - 1.0).abs() < 7e-10,
            "{v:?}"
        );
        // from the bottom nothing is packed: the lowest band is empty
        let bottom = PackedZone { top: false, ..pz };
        assert!(bottom.sample(&sys)[0].is_nan());
    }

    #[test]
    fn the_interior_fraction_leaves_out_the_ragged_lower_band() {
        // Four full rows of touching discs under the top of the box and a fifth row with every
        // other disc: bands of 0.1 hold π/4 each, the fifth π/8. The zone's fraction falls with
        // the ragged band; the interior (bands 2-4) stays π/4.
        let (b, pz) = rows_of_discs(5, |row, i| row < 4 || i % 2 == 0);
        let sys = System::new(b, Domain::open(Vec2::ZERO, Vec2::new(1.0, 1.0)));
        let [fraction, height, _] = pz.sample(&sys)[..] else {
            panic!("three columns")
        };
        let quarter = std::f64::consts::FRAC_PI_4;
        // Measured 3.3e-10 off, from the bodies' mass properties (as above).
        assert!((height - 0.5).abs() < 1e-12);
        assert!((fraction - 0.9 * quarter).abs() < 7e-10, "{fraction}");
        let b = &sys.bodies;
        let grains = (0..b.len()).map(|k| {
            let circles =
                (b.circle_start[k]..b.circle_start[k + 1]).map(move |c| (b.circle_pos(c).y, b.circle_r[c]));
            (b.mass[k] / b.density[k], true, circles)
        });
        let (bands, _) = pz.bands(grains);
        assert!((interior_fraction(&bands) - quarter).abs() < 7e-10);
        // Two bands: no interior.
        assert!(
            interior_fraction(
                &bands[..2]
                    .iter()
                    .map(|b| Band { still: true, ..*b })
                    .collect::<Vec<_>>()
            )
            .is_nan()
        );
    }

    #[test]
    fn a_disc_split_by_a_band_edge_counts_its_two_halves() {
        let half = disc_between(0.0, 1.0, 0.0, 5.0);
        assert!((half - std::f64::consts::FRAC_PI_2).abs() < 1e-14);
        assert!((disc_between(0.0, 1.0, -5.0, 5.0) - std::f64::consts::PI).abs() < 1e-14);
    }
}
