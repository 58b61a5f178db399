//! File I/O of the root crate (kernel crates never touch files). `tiff`: 8/16-bit integer
//! and 32-bit float grey TIFF in (single frames, multi-page stacks, numbered frame
//! directories; uncompressed, deflate, LZW, PackBits), 16-bit and 32-bit float out.

pub mod tiff;
