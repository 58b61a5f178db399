//! TIFF frames in and out. Reading converts every supported sample type to f64 (NaN kept,
//! it marks masked pixels); writing encodes in memory and then writes atomically.

use anyhow::{Context, Result, bail};
use ndarray::{Array2, ArrayView2};
use std::io::Cursor;
use std::path::{Path, PathBuf};
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};

/// One frame read from a file: which file and page, and its pixels.
#[derive(Clone, Debug)]
pub struct Frame {
    /// `file` for a single image, `file#page` inside a stack (page from 0).
    pub label: String,
    pub data: Array2<f64>,
    /// Bits per sample of the source (8, 16, 32 or 64).
    pub bits: u8,
}

/// Every TIFF page of `path` (a stack yields several frames).
pub fn read_pages(path: &Path) -> Result<Vec<Frame>> {
    let file = std::fs::File::open(path).with_context(|| {
        format!(
            "cannot open TIFF file {} (check the path in 'frames'/'dark'/'flat')",
            path.display()
        )
    })?;
    let mut dec = Decoder::new(std::io::BufReader::new(file))
        .with_context(|| format!("{} is not a readable TIFF file", path.display()))?
        .with_limits(Limits::unlimited());
    let mut frames = Vec::new();
    loop {
        let page = frames.len();
        let label = if page == 0 {
            path.display().to_string()
        } else {
            format!("{}#{page}", path.display())
        };
        let (w, h) = dec
            .dimensions()
            .with_context(|| format!("{label}: cannot read the image size"))?;
        let ct = dec
            .colortype()
            .with_context(|| format!("{label}: cannot read the pixel type"))?;
        let bits = match ct {
            ColorType::Gray(b @ (8 | 16 | 32 | 64)) => b,
            other => bail!(
                "{label}: unsupported pixel type {other:?}; lbdem reads single-channel (grey) TIFF with \
                 8- or 16-bit unsigned integer or 32-bit float samples: convert the file (e.g. with \
                 ImageJ or tifffile) to one of these"
            ),
        };
        let img = dec
            .read_image()
            .with_context(|| format!("{label}: cannot decode the pixel data"))?;
        let v: Vec<f64> = match img {
            DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
            DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
            DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
            DecodingResult::F64(v) => v,
            other => bail!(
                "{label}: unsupported {bits}-bit sample format ({}); lbdem reads 8/16-bit unsigned integer \
                 or 32-bit float samples",
                match other {
                    DecodingResult::U32(_) => "32-bit unsigned integer",
                    DecodingResult::I8(_) | DecodingResult::I16(_) | DecodingResult::I32(_) =>
                        "signed integer",
                    _ => "other",
                }
            ),
        };
        let data = Array2::from_shape_vec((h as usize, w as usize), v)
            .with_context(|| format!("{label}: pixel count does not match {w}x{h}"))?;
        frames.push(Frame { label, data, bits });
        if !dec.more_images() {
            break;
        }
        dec.next_image()
            .with_context(|| format!("{}: cannot read page {}", path.display(), page + 1))?;
    }
    Ok(frames)
}

/// Expand the `frames` list: a directory becomes its `*.tif`/`*.tiff` files in natural
/// order (frame_2 before frame_10); files stay as given. Missing paths are an error.
pub fn expand_paths(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut v: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("cannot list frame directory {}", p.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|q| {
                    q.extension()
                        .and_then(|e| e.to_str())
                        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
                })
                .collect();
            if v.is_empty() {
                bail!("frame directory {} holds no .tif/.tiff files", p.display());
            }
            v.sort_by_key(|a| natural_key(a));
            out.extend(v);
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            bail!(
                "frame file {} does not exist (check 'frames' in the parameters)",
                p.display()
            );
        }
    }
    Ok(out)
}

/// Sort key splitting digit runs out as numbers.
fn natural_key(p: &Path) -> Vec<(String, u64)> {
    let name = p
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut key = Vec::new();
    let mut text = String::new();
    let mut num = String::new();
    for ch in name.chars() {
        if ch.is_ascii_digit() {
            num.push(ch);
        } else {
            if !num.is_empty() {
                key.push((std::mem::take(&mut text), num.parse().unwrap_or(u64::MAX)));
                num.clear();
            }
            text.push(ch);
        }
    }
    key.push((text, num.parse().unwrap_or(0)));
    key
}

/// Read every frame of every path (directories expanded, stacks split into pages).
pub fn read_frames(paths: &[PathBuf]) -> Result<Vec<Frame>> {
    let mut out = Vec::new();
    for p in expand_paths(paths)? {
        out.extend(read_pages(&p)?);
    }
    Ok(out)
}

/// Read a single-frame file (dark or flat field); a stack is averaged page by page.
pub fn read_mean(path: &Path) -> Result<Frame> {
    let pages = read_pages(path)?;
    let n = pages.len() as f64;
    let mut it = pages.into_iter();
    let mut first = it.next().context("TIFF file has no pages")?;
    for p in it {
        if p.data.dim() != first.data.dim() {
            bail!("{}: pages of different sizes cannot be averaged", path.display());
        }
        first.data += &p.data;
    }
    first.data /= n;
    Ok(first)
}

fn dims(f: &ArrayView2<f64>) -> Result<(u32, u32)> {
    let (h, w) = f.dim();
    Ok((u32::try_from(w)?, u32::try_from(h)?))
}

/// 32-bit float TIFF, deflate-compressed, written atomically (NaN kept as NaN).
pub fn write_f32(path: &Path, f: ArrayView2<f64>) -> Result<()> {
    let (w, h) = dims(&f)?;
    let v: Vec<f32> = f.iter().map(|&x| x as f32).collect();
    let mut buf = Cursor::new(Vec::new());
    TiffEncoder::new(&mut buf)?
        .with_compression(Compression::Deflate(DeflateLevel::Fast))
        .write_image::<colortype::Gray32Float>(w, h, &v)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    lbdem_core::atomic::write_atomic(path, buf.get_ref())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// 16-bit unsigned TIFF, deflate-compressed, written atomically.
pub fn write_u16(path: &Path, f: ArrayView2<u16>) -> Result<()> {
    let (h, w) = f.dim();
    let v: Vec<u16> = f.iter().copied().collect();
    let mut buf = Cursor::new(Vec::new());
    TiffEncoder::new(&mut buf)?
        .with_compression(Compression::Deflate(DeflateLevel::Balanced))
        .write_image::<colortype::Gray16>(u32::try_from(w)?, u32::try_from(h)?, &v)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    lbdem_core::atomic::write_atomic(path, buf.get_ref())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Multi-page 16-bit stack (uncompressed), for tests and synthetic stacks.
pub fn write_u16_stack(path: &Path, frames: &[ArrayView2<u16>]) -> Result<()> {
    let mut buf = Cursor::new(Vec::new());
    let mut enc = TiffEncoder::new(&mut buf)?;
    for f in frames {
        let (h, w) = f.dim();
        let v: Vec<u16> = f.iter().copied().collect();
        enc.write_image::<colortype::Gray16>(u32::try_from(w)?, u32::try_from(h)?, &v)?;
    }
    lbdem_core::atomic::write_atomic(path, buf.get_ref())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// 8-bit TIFF (tests of the reader).
pub fn write_u8(path: &Path, f: ArrayView2<u8>) -> Result<()> {
    let (h, w) = f.dim();
    let v: Vec<u8> = f.iter().copied().collect();
    let mut buf = Cursor::new(Vec::new());
    TiffEncoder::new(&mut buf)?.write_image::<colortype::Gray8>(u32::try_from(w)?, u32::try_from(h)?, &v)?;
    lbdem_core::atomic::write_atomic(path, buf.get_ref())
        .with_context(|| format!("cannot write {}", path.display()))
}
