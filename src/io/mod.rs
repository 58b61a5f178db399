//! File I/O of the root crate (kernel crates never touch files). `tiff`: 8/16-bit integer
//! and 32-bit float grey TIFF in (single frames, multi-page stacks, numbered frame
//! directories; uncompressed, deflate, LZW, PackBits), 16-bit and 32-bit float out. `image`:
//! PNG, JPEG and colour TIFF through the `image` crate. Both decode with limits on memory, so a
//! damaged or hostile header is an error, never an abort.

pub mod image;
pub mod tiff;
