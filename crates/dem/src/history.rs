//! Per-contact history, law-agnostic. Each contact law declares its own history type
//! ([`crate::ContactLaw::History`]: plain data, [`HistoryData`]); [`Histories`] stores one record
//! per contact as `stride` f64 slots in one `Vec<f64>`, so [`crate::System`] stays non-generic
//! and serialisable whatever the law, and typed views (`&[H]`, by `bytemuck` casts, no copy) give
//! each law its own records back. A store holds the layout of one law at a time: viewed with a
//! type of another stride, its records restart from `H::default()`.

use crate::contact::History;
use bytemuck::Pod;
use serde::{Deserialize, Serialize};
use std::fmt::Debug;

/// What a contact law may keep per contact: plain data (`bytemuck::Pod`: no padding, every bit
/// pattern valid, e.g. `#[repr(C)]` structs of f64/u64/i64/u32 pairs) of whole f64 slots (size a
/// multiple of 8 bytes, alignment at most 8). `Default` is the state of a fresh contact (it must
/// be all zero bits for a law registered in [`crate::Law`], whose records are shared).
pub trait HistoryData: Pod + Default + PartialEq + Debug + Send + Sync {}

impl<T: Pod + Default + PartialEq + Debug + Send + Sync> HistoryData for T {}

/// f64 slots per record of `H` (compile-time check of the layout rules of [`HistoryData`]).
pub const fn stride_of<H: HistoryData>() -> usize {
    assert!(
        size_of::<H>().is_multiple_of(8) && align_of::<H>() <= 8,
        "a contact history must be whole f64 slots (size a multiple of 8, alignment <= 8)"
    );
    size_of::<H>() / 8
}

/// `len` history records of `stride` f64 each (see the module docs).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawHistories")]
pub struct Histories {
    stride: usize,
    len: usize,
    data: Vec<f64>,
}

/// The serialised form, checked on the way in.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawHistories {
    Slots {
        stride: usize,
        len: usize,
        data: Vec<f64>,
    },
    /// Checkpoints written before histories were law-agnostic: a list of [`History`].
    Legacy(Vec<History>),
}

impl TryFrom<RawHistories> for Histories {
    type Error = String;
    fn try_from(r: RawHistories) -> Result<Self, String> {
        match r {
            RawHistories::Legacy(h) => Ok(Self::from_slice(&h)),
            RawHistories::Slots { stride, len, data } => {
                if stride.checked_mul(len) != Some(data.len()) {
                    return Err(format!(
                        "contact histories: {len} records of {stride} slots need {} numbers, found {}",
                        stride.saturating_mul(len),
                        data.len()
                    ));
                }
                Ok(Self { stride, len, data })
            }
        }
    }
}

impl Histories {
    /// A store holding `h`.
    pub fn from_slice<H: HistoryData>(h: &[H]) -> Self {
        let mut s = Self::default();
        s.reset::<H>(h.len());
        s.view_mut::<H>().copy_from_slice(h);
        s
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// f64 slots per record.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Record `k` as raw slots.
    pub fn record(&self, k: usize) -> Option<&[f64]> {
        (k < self.len).then(|| &self.data[k * self.stride..(k + 1) * self.stride])
    }

    /// Every record as raw slots, in order.
    pub fn records(&self) -> impl Iterator<Item = &[f64]> + '_ {
        (0..self.len).map(move |k| &self.data[k * self.stride..(k + 1) * self.stride])
    }

    /// The records as `H`, if they have its layout.
    pub fn as_slice<H: HistoryData>(&self) -> Option<&[H]> {
        (self.stride == const { stride_of::<H>() }).then(|| self.view::<H>())
    }

    /// The records as `H`, mutable, if they have its layout.
    pub fn as_mut_slice<H: HistoryData>(&mut self) -> Option<&mut [H]> {
        (self.stride == const { stride_of::<H>() }).then(|| self.view_mut::<H>())
    }

    /// `n` records of `H::default()`.
    pub(crate) fn reset<H: HistoryData>(&mut self, n: usize) {
        self.stride = const { stride_of::<H>() };
        self.len = n;
        self.data.clear();
        self.data.resize(n * self.stride, 0.0);
        self.view_mut::<H>().fill(H::default());
    }

    /// `n` records of `H`: kept if the store already holds `n` of that layout, else reset.
    pub(crate) fn conform<H: HistoryData>(&mut self, n: usize) -> &mut [H] {
        if self.stride != const { stride_of::<H>() } || self.len != n || self.data.len() != n * self.stride {
            self.reset::<H>(n);
        }
        self.view_mut::<H>()
    }

    /// `n` records of `H`: the first ones kept if the store holds `H`'s layout, the others fresh.
    pub(crate) fn resize<H: HistoryData>(&mut self, n: usize) {
        if self.stride != const { stride_of::<H>() } || self.data.len() != self.len * self.stride {
            self.reset::<H>(n);
        } else if n != self.len {
            let keep = n.min(self.len);
            self.data.resize(n * self.stride, 0.0);
            self.len = n;
            self.view_mut::<H>()[keep..].fill(H::default());
        }
    }

    fn view<H: HistoryData>(&self) -> &[H] {
        if size_of::<H>() == 0 {
            // SAFETY: a dangling, aligned pointer is a valid slice of zero-sized values.
            return unsafe {
                std::slice::from_raw_parts(std::ptr::NonNull::<H>::dangling().as_ptr(), self.len)
            };
        }
        // `stride_of` guarantees size % 8 == 0 and align <= 8: the cast cannot fail.
        bytemuck::cast_slice(&self.data)
    }

    fn view_mut<H: HistoryData>(&mut self) -> &mut [H] {
        if size_of::<H>() == 0 {
            // SAFETY: as in `view`.
            return unsafe {
                std::slice::from_raw_parts_mut(std::ptr::NonNull::<H>::dangling().as_ptr(), self.len)
            };
        }
        bytemuck::cast_slice_mut(&mut self.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vector::Vec2;

    #[test]
    fn reads_both_forms_and_refuses_a_short_record_list() {
        let h = History {
            xi_t: Vec2::new(0.1, -2.5e-7),
            theta_r: 3.0,
            delta_p: 0.0,
        };
        let new = Histories::from_slice(&[h, History::default()]);
        let json = serde_json::to_string(&new).unwrap();
        let back: Histories = serde_json::from_str(&json).unwrap();
        assert_eq!(back, new);
        let legacy: Histories =
            serde_json::from_str(&serde_json::to_string(&[h, History::default()]).unwrap()).unwrap();
        assert_eq!(legacy, new);
        assert_eq!(legacy.as_slice::<History>(), Some(&[h, History::default()][..]));
        assert_eq!(legacy.as_slice::<[f64; 2]>(), None);
        let bad = r#"{"stride": 4, "len": 2, "data": [1.0, 2.0]}"#;
        let err = serde_json::from_str::<Histories>(bad).unwrap_err().to_string();
        assert!(err.contains("need 8 numbers, found 2"), "{err}");
    }
}
