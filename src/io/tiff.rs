//! TIFF frames in and out. Reading converts every supported sample type to f64 (NaN kept,
//! it marks masked pixels); writing encodes in memory and then writes atomically.

use anyhow::{Context, Result, bail};
use ndarray::{Array2, ArrayView2};
use std::io::{Cursor, Read, Seek};
use std::path::{Path, PathBuf};
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};
use tiff::tags::Tag;

/// One frame read from a file: which file and page, and its pixels.
#[derive(Clone, Debug)]
pub struct Frame {
    /// `file` for a single image, `file#page` inside a stack (page from 0).
    pub label: String,
    pub data: Array2<f64>,
    /// Bits per sample of the source (8, 16, 32 or 64).
    pub bits: u8,
}

/// The largest decoded page lbdem accepts, in bytes: a 4096 × 4096 frame of 64-bit samples
/// (128 MiB). The largest real detector frame the project reads is Su et al. 2020's 2048 × 2048
/// 16-bit (8 MiB); the limit leaves room for 4k flat panels and float maps, and stops a header
/// that claims more (a 300-byte file claiming 200000 × 200000 pixels asked for 80 GB) before
/// anything is allocated.
pub const MAX_FRAME_BYTES: usize = 4096 * 4096 * 8;

/// The most pixels one file (all pages of a stack) may hold: 2^29 (4 GiB as f64, e.g. 128
/// frames of 2048 × 2048). Pages can share their pixel data, so a small file could otherwise
/// claim any number of full-size pages.
pub const MAX_FILE_PIXELS: u64 = 1 << 29;

/// Decoding limits of the `tiff` crate for lbdem's frames: the page limit above; tag values
/// (strip offsets and counts, 8 bytes per strip) up to 4 MiB, which a 4096-row page with one row
/// per strip needs 64 KiB of.
fn limits() -> Limits {
    let mut l = Limits::default();
    l.decoding_buffer_size = MAX_FRAME_BYTES;
    l.intermediate_buffer_size = MAX_FRAME_BYTES;
    l.ifd_value_size = 4 << 20;
    l
}

/// Every TIFF page of `path` (a stack yields several frames).
pub fn read_pages(path: &Path) -> Result<Vec<Frame>> {
    pages(path)?.map(|p| p.map(Page::into_frame)).collect()
}

fn open(path: &Path) -> Result<std::io::BufReader<std::fs::File>> {
    let file = std::fs::File::open(path).with_context(|| {
        format!(
            "cannot open TIFF file {} (check the path in 'frames'/'dark'/'flat')",
            path.display()
        )
    })?;
    Ok(std::io::BufReader::new(file))
}

/// The pages of the TIFF file `path`, decoded one at a time as they are asked for.
pub fn pages(path: &Path) -> Result<Pages<std::io::BufReader<std::fs::File>>> {
    Pages::new(open(path)?, &path.display().to_string())
}

/// Every TIFF page of the bytes `r` yields, labelled `name` in errors (the file's path). Memory
/// is bounded by [`MAX_FRAME_BYTES`] per page and [`MAX_FILE_PIXELS`] per file whatever the
/// header claims; bad input is an error, never a panic or an abort.
pub fn read_pages_from<R: Read + Seek>(r: R, name: &str) -> Result<Vec<Frame>> {
    Pages::new(r, name)?.map(|p| p.map(Page::into_frame)).collect()
}

/// A page's pixels as stored: 16-bit counts stay 16-bit (the radiograph stage reads them through
/// a lookup table: no f64 copy of a 2048² frame), every other sample type becomes f64.
#[derive(Clone, Debug)]
pub enum Pixels {
    U16(Array2<u16>),
    F64(Array2<f64>),
}

impl Pixels {
    /// (rows, columns).
    pub fn dim(&self) -> (usize, usize) {
        match self {
            Pixels::U16(a) => a.dim(),
            Pixels::F64(a) => a.dim(),
        }
    }
    pub fn into_f64(self) -> Array2<f64> {
        match self {
            Pixels::U16(a) => a.mapv(f64::from),
            Pixels::F64(a) => a,
        }
    }
}

/// One decoded page.
#[derive(Clone, Debug)]
pub struct Page {
    /// As [`Frame::label`].
    pub label: String,
    pub bits: u8,
    pub pixels: Pixels,
}

impl Page {
    pub fn into_frame(self) -> Frame {
        Frame {
            label: self.label,
            bits: self.bits,
            data: self.pixels.into_f64(),
        }
    }
}

/// What a page's header says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PageInfo {
    pub label: String,
    pub rows: usize,
    pub cols: usize,
    pub bits: u8,
}

/// The headers of every page of `path`, without decoding pixels: how many frames a stack holds
/// and their sizes, checked before a stage reads the first frame.
pub fn probe_pages(path: &Path) -> Result<Vec<PageInfo>> {
    let mut p = pages(path)?;
    let mut out = Vec::new();
    loop {
        out.push(p.header()?);
        if !p.advance()? {
            return Ok(out);
        }
    }
}

/// The pages of one TIFF file as an iterator: one page decoded per `next`, so a stack of
/// hundreds of frames needs one frame's memory at a time. After an error it yields nothing.
pub struct Pages<R: Read + Seek> {
    dec: Decoder<R>,
    name: String,
    page: usize,
    pixels: u64,
    done: bool,
}

impl<R: Read + Seek> Pages<R> {
    pub fn new(r: R, name: &str) -> Result<Self> {
        let dec = Decoder::new(r)
            .with_context(|| format!("{name} is not a readable TIFF file"))?
            .with_limits(limits());
        Ok(Self {
            dec,
            name: name.to_string(),
            page: 0,
            pixels: 0,
            done: false,
        })
    }

    fn label(&self) -> String {
        if self.page == 0 {
            self.name.clone()
        } else {
            format!("{}#{}", self.name, self.page)
        }
    }

    /// The current page's header, checked against the per-page and per-file limits.
    fn header(&mut self) -> Result<PageInfo> {
        let label = self.label();
        let (w, h) = self
            .dec
            .dimensions()
            .with_context(|| format!("{label}: cannot read the image size"))?;
        let ct = self
            .dec
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
        // The sample format from the header (absent = unsigned), so a stage that reads pixels
        // later refuses a 32-bit integer frame before it writes anything.
        let format = match self.dec.find_tag(Tag::SampleFormat) {
            Ok(Some(v)) => v
                .into_u32_vec()
                .ok()
                .and_then(|v| v.first().copied())
                .unwrap_or(0),
            Ok(None) => 1,
            Err(_) => 0,
        };
        if !matches!((bits, format), (8 | 16, 1) | (32 | 64, 3)) {
            bail!(
                "{label}: unsupported {bits}-bit sample format ({bits}-bit {}); lbdem reads 8/16-bit unsigned \
                 integer or 32-bit float samples",
                match format {
                    1 => "unsigned integer",
                    2 => "signed integer",
                    3 => "float",
                    _ => "other",
                }
            );
        }
        let bytes = u64::from(w) * u64::from(h) * u64::from(bits / 8);
        if bytes > MAX_FRAME_BYTES as u64 {
            bail!(
                "{label}: the header says {w} x {h} pixels of {bits} bits ({:.1} MiB), above lbdem's limit of \
                 {} MiB per frame (4096 x 4096 x 64 bits; Su et al.'s detector gives 2048 x 2048 x 16 bits = \
                 8 MiB); if the file is a real frame, crop or bin it, else it is damaged",
                bytes as f64 / f64::from(1 << 20),
                MAX_FRAME_BYTES >> 20
            );
        }
        self.pixels += u64::from(w) * u64::from(h);
        if self.pixels > MAX_FILE_PIXELS {
            bail!(
                "{label}: the stack holds more than {MAX_FILE_PIXELS} pixels in {} pages, above lbdem's limit per \
                 file; split the stack into several files (a directory of frames is read in order)",
                self.page + 1
            );
        }
        Ok(PageInfo {
            label,
            rows: h as usize,
            cols: w as usize,
            bits,
        })
    }

    /// Move to the next page; false after the last.
    fn advance(&mut self) -> Result<bool> {
        if !self.dec.more_images() {
            return Ok(false);
        }
        self.dec
            .next_image()
            .with_context(|| format!("{}: cannot read page {}", self.name, self.page + 1))?;
        self.page += 1;
        Ok(true)
    }

    fn decode(&mut self) -> Result<Page> {
        let PageInfo {
            label,
            rows,
            cols,
            bits,
        } = self.header()?;
        let img = self
            .dec
            .read_image()
            .with_context(|| format!("{label}: cannot decode the pixel data"))?;
        let shaped = |n: usize| {
            if n == rows * cols {
                Ok((rows, cols))
            } else {
                Err(anyhow::anyhow!(
                    "{label}: pixel count does not match {cols}x{rows}"
                ))
            }
        };
        let pixels = match img {
            DecodingResult::U16(v) => Pixels::U16(Array2::from_shape_vec(shaped(v.len())?, v)?),
            DecodingResult::U8(v) => Pixels::F64(Array2::from_shape_vec(
                shaped(v.len())?,
                v.into_iter().map(f64::from).collect(),
            )?),
            DecodingResult::F32(v) => Pixels::F64(Array2::from_shape_vec(
                shaped(v.len())?,
                v.into_iter().map(f64::from).collect(),
            )?),
            DecodingResult::F64(v) => Pixels::F64(Array2::from_shape_vec(shaped(v.len())?, v)?),
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
        Ok(Page { label, bits, pixels })
    }
}

impl<R: Read + Seek> Iterator for Pages<R> {
    type Item = Result<Page>;
    fn next(&mut self) -> Option<Result<Page>> {
        if self.done {
            return None;
        }
        let page = self.decode().and_then(|p| {
            self.done = !self.advance()?;
            Ok(p)
        });
        self.done |= page.is_err();
        Some(page)
    }
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

/// 32-bit float TIFF, uncompressed, written atomically (NaN kept as NaN).
///
/// Uncompressed because deflate does not pay on these maps: a 2048² REV g_S map came out at
/// 17.6 MB deflated against 16.8 MB raw (float noise does not compress), and deflating was 44 % of
/// `lbdem radiograph`'s time on eight such frames (issue 18 item 5).
pub fn write_f32(path: &Path, f: ArrayView2<f64>) -> Result<()> {
    let (w, h) = dims(&f)?;
    let v: Vec<f32> = f.iter().map(|&x| x as f32).collect();
    // Encoded straight into the file's buffered writer: no second copy of the map in memory.
    lbdem_core::atomic::write_atomic_with(path, |out| {
        TiffEncoder::new(out)
            .and_then(|mut e| e.write_image::<colortype::Gray32Float>(w, h, &v))
            .map_err(std::io::Error::other)
    })
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
