//! `[packed_zone]`: the layer floating grains pack into (Su et al. 2020 Sect. 3.2, Fig. 5b-c, h):
//! where it forms, what counts as packed, and the band height of the packing profile.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PackedZoneSection {
    /// The side of the box the grains pack against: "top" (grains lighter than the liquid)
    /// or "bottom".
    #[serde(default = "top")]
    pub side: String,
    /// A band is packed while its fastest grain is slower than this (m/s). Su's radiographs
    /// count a grain as packed when it moved less than 2 µm in 10 s: 2e-7 m/s.
    #[serde(default = "two_um_in_ten_s")]
    pub slower_than: f64,
    /// Height of the bands (m); a few mean diameters.
    pub band: f64,
}

fn top() -> String {
    "top".into()
}
fn two_um_in_ten_s() -> f64 {
    2e-7
}
