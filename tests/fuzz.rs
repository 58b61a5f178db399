//! Fuzz harnesses of every reader of user input: each mutates real seed inputs (a few bytes
//! flipped, interesting integers written over headers, numbers replaced by NaN, −1 or 1e308,
//! lines deleted or repeated, chunks spliced) and feeds them to the reader, asserting no
//! panic, no abort and bounded memory (a counting allocator measures each execution's peak).
//! Inputs are generated and shrunk by proptest, so a failure reports a minimal input.
//!
//! CI runs a short budget of each (`cargo test`); the long campaign:
//! `LBDEM_FUZZ_EXECS=1000000 cargo test --release --test fuzz -- --nocapture --test-threads 1`
//! (`scripts/fuzz.sh`; docs/fuzzing.md has the counts and wall times reached). A crash found
//! becomes a regression test beside the reader's other tests.
//!
//! Adding a reader: one line in the `targets!` list at the bottom (name, seeds, what to call).

use lbdem::contract::StageContext;
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

// ---------------------------------------------------------------------------------------------
// Memory: a counting allocator (every thread, so polars' and rayon's workers count too).

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = CURRENT.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(l) };
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
            grew(new);
        }
        q
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// One target at a time, so the peak belongs to it.
static SERIAL: Mutex<()> = Mutex::new(());

// ---------------------------------------------------------------------------------------------
// Time: a watchdog bounds each execution, so a hang fails the harness instead of stalling it
// (checkpoint_coupled once stalled a campaign for 12 minutes before anyone noticed).

/// The execution under way: its harness, when it started, and its input (kept for the report).
struct Running {
    name: String,
    started: Option<Instant>,
    input: Vec<u8>,
}

static RUNNING: Mutex<Running> = Mutex::new(Running {
    name: String::new(),
    started: None,
    input: Vec::new(),
});

/// Seconds one execution may take: `LBDEM_FUZZ_TIMEOUT_S`, else 60. The slowest harness,
/// checkpoint_extruder, takes 0.65 ms per execution in release (650 s for 10^6 at 30c09a6) and
/// its slowest seed well under a second in the test profile, so 60 s is a hang, not a slow input.
fn time_bound() -> Duration {
    let secs = std::env::var("LBDEM_FUZZ_TIMEOUT_S")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(60.0);
    Duration::from_secs_f64(secs)
}

/// Starts the watchdog once: every 100 ms it looks at the execution under way, and when one has
/// run past the bound it writes the input to `LBDEM_FUZZ_DUMP` (else a file under the target
/// directory), names both, and ends the test process with a failure.
fn watchdog() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let bound = time_bound();
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(100));
                let running = RUNNING.lock().unwrap_or_else(|p| p.into_inner());
                let Some(started) = running.started else { continue };
                if started.elapsed() <= bound {
                    continue;
                }
                let file = std::env::var_os("LBDEM_FUZZ_DUMP").map(PathBuf::from).unwrap_or_else(|| {
                    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz-hang-{}.bin", running.name))
                });
                let kept = match std::fs::write(&file, &running.input) {
                    Ok(()) => format!("its {}-byte input is in {}", running.input.len(), file.display()),
                    Err(e) => format!("its input could not be written to {}: {e}", file.display()),
                };
                eprintln!(
                    "fuzz {}: one execution has run for more than {} s (LBDEM_FUZZ_TIMEOUT_S): a hang; {kept}. \
                     Feed that file to the reader in a test, find what the reader accepted that it should refuse, \
                     and make that a regression test.",
                    running.name,
                    bound.as_secs_f64()
                );
                std::process::exit(101);
            }
        });
    });
}

// ---------------------------------------------------------------------------------------------
// Mutations.

/// Values that break parsers: header fields at their limits, and numbers no scene should hold.
const INTERESTING: &[u64] = &[
    0,
    1,
    2,
    7,
    8,
    0x7f,
    0x80,
    0xff,
    0x100,
    2048,
    4096,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    200_000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
];

const TOKENS: &[&str] = &[
    "nan",
    "-nan",
    "inf",
    "-inf",
    "NaN",
    "-1",
    "0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-320",
    "18446744073709551616",
    "9223372036854775807",
    "-9223372036854775808",
    "4294967296",
    "0.5",
    "1e9",
    "\"\"",
    "\"x\"",
    "[]",
    "{}",
    "[1.0, 2.0, 3.0]",
    "[[1.0]]",
    "true",
    "\n[x]\n",
    "\n[[walls]]\n",
    "=",
    ",",
    "\n",
    "#",
    "\"",
    "{ a = 1 }",
    ",,,,",
    "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16",
];

#[derive(Clone, Debug)]
enum Op {
    Flip(Index, u8),
    Set(Index, u8),
    Interesting(Index, u8, Index),
    Insert(Index, Vec<u8>),
    Delete(Index, u8),
    Truncate(Index),
    Splice(Index, u8, Index),
    Token(Index, Index),
    Line(Index, bool),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(i, b)| Op::Flip(i, b)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Op::Set(i, b)),
        (
            any::<Index>(),
            prop_oneof![Just(1u8), Just(2), Just(4)],
            any::<Index>()
        )
            .prop_map(|(i, w, v)| Op::Interesting(i, w, v)),
        (any::<Index>(), proptest::collection::vec(any::<u8>(), 1..8)).prop_map(|(i, v)| Op::Insert(i, v)),
        (any::<Index>(), 1u8..32).prop_map(|(i, n)| Op::Delete(i, n)),
        any::<Index>().prop_map(Op::Truncate),
        (any::<Index>(), 1u8..64, any::<Index>()).prop_map(|(i, n, j)| Op::Splice(i, n, j)),
        (any::<Index>(), any::<Index>()).prop_map(|(i, t)| Op::Token(i, t)),
        (any::<Index>(), any::<bool>()).prop_map(|(i, dup)| Op::Line(i, dup)),
    ]
}

/// The start and end of the token (a run of number/word characters) at `at`.
fn token_at(b: &[u8], at: usize) -> (usize, usize) {
    let word = |c: u8| c.is_ascii_alphanumeric() || matches!(c, b'.' | b'-' | b'+' | b'_');
    let (mut s, mut e) = (at, at);
    while s > 0 && word(b[s - 1]) {
        s -= 1;
    }
    while e < b.len() && word(b[e]) {
        e += 1;
    }
    (s, e)
}

fn apply(seed: &[u8], ops: &[Op]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for o in ops {
        let n = b.len();
        if n == 0 {
            if let Op::Insert(_, v) = o {
                b.extend(v);
            }
            continue;
        }
        match o {
            Op::Flip(i, bit) => b[i.index(n)] ^= 1 << bit,
            Op::Set(i, v) => b[i.index(n)] = *v,
            Op::Interesting(i, w, v) => {
                let x = INTERESTING[v.index(INTERESTING.len())];
                let at = i.index(n);
                for k in 0..usize::from(*w) {
                    if at + k < n {
                        b[at + k] = (x >> (8 * k)) as u8;
                    }
                }
            }
            Op::Insert(i, v) => {
                let at = i.index(n + 1);
                b.splice(at..at, v.iter().copied());
            }
            Op::Delete(i, len) => {
                let at = i.index(n);
                b.drain(at..(at + usize::from(*len)).min(n));
            }
            Op::Truncate(i) => b.truncate(i.index(n)),
            Op::Splice(i, len, j) => {
                let from = i.index(n);
                let chunk: Vec<u8> = b[from..(from + usize::from(*len)).min(n)].to_vec();
                let to = j.index(n + 1);
                b.splice(to..to, chunk);
            }
            Op::Token(i, t) => {
                let (s, e) = token_at(&b, i.index(n));
                let tok = TOKENS[t.index(TOKENS.len())].as_bytes();
                b.splice(s..e, tok.iter().copied());
            }
            Op::Line(i, dup) => {
                let at = i.index(n);
                let s = b[..at].iter().rposition(|&c| c == b'\n').map_or(0, |p| p + 1);
                let e = b[at..].iter().position(|&c| c == b'\n').map_or(n, |p| at + p + 1);
                if *dup {
                    let line = b[s..e].to_vec();
                    b.splice(e..e, line);
                } else {
                    b.drain(s..e);
                }
            }
        }
    }
    b
}

// ---------------------------------------------------------------------------------------------
// The runner.

/// Executions per target: `LBDEM_FUZZ_EXECS`, else the CI budget (seconds per target).
fn execs(ci: u32) -> u32 {
    std::env::var("LBDEM_FUZZ_EXECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(ci)
}

/// Fuzz `target` (returns whether the input was accepted) from `seeds`: no panic, and no
/// execution's peak allocation above `bound(input length)` bytes.
fn fuzz(name: &str, ci: u32, seeds: Vec<Vec<u8>>, bound: fn(usize) -> usize, target: &dyn Fn(&[u8]) -> bool) {
    let _one = SERIAL.lock().unwrap_or_else(|p| p.into_inner());
    assert!(!seeds.is_empty(), "{name}: no seeds");
    // The seeds themselves must read (else the target tests only refusals).
    let accepted_seeds = seeds.iter().filter(|s| target(s)).count();
    assert!(accepted_seeds > 0, "{name}: no seed is accepted by the reader");
    let n = execs(ci);
    let seed: u64 = std::env::var("LBDEM_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(17);
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    key[8..8 + name.len().min(24)].copy_from_slice(&name.as_bytes()[..name.len().min(24)]);
    let config = Config {
        cases: n,
        failure_persistence: None,
        max_shrink_iters: 4096,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &key));
    let (accepted, refused, worst) = (AtomicUsize::new(0), AtomicUsize::new(0), AtomicUsize::new(0));
    let t0 = Instant::now();
    let strategy = (0..seeds.len(), proptest::collection::vec(op(), 1..6));
    // LBDEM_FUZZ_DUMP=FILE keeps the input being executed in FILE: after a hang (a run stopped
    // by `timeout`), FILE holds the input that hung.
    let dump = std::env::var_os("LBDEM_FUZZ_DUMP");
    watchdog();
    RUNNING.lock().unwrap_or_else(|p| p.into_inner()).name = name.to_string();
    let result = runner.run(&strategy, |(s, ops)| {
        let input = apply(&seeds[s], &ops);
        if let Some(f) = &dump {
            std::fs::write(f, &input).expect("LBDEM_FUZZ_DUMP: the file cannot be written");
        }
        {
            let mut running = RUNNING.lock().unwrap_or_else(|p| p.into_inner());
            running.input.clone_from(&input);
            running.started = Some(Instant::now());
        }
        let base = CURRENT.load(Ordering::Relaxed);
        PEAK.store(base, Ordering::Relaxed);
        let ok = target(&input);
        RUNNING.lock().unwrap_or_else(|p| p.into_inner()).started = None;
        let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
        worst.fetch_max(peak, Ordering::Relaxed);
        [&refused, &accepted][usize::from(ok)].fetch_add(1, Ordering::Relaxed);
        if peak > bound(input.len()) {
            return Err(TestCaseError::fail(format!(
                "{name}: one execution allocated {peak} bytes at its peak, above the bound {} for a {}-byte input",
                bound(input.len()),
                input.len()
            )));
        }
        Ok(())
    });
    let secs = t0.elapsed().as_secs_f64();
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    eprintln!(
        "fuzz {name}: {n} executions in {secs:.1} s ({:.0}/s): {} accepted, {} refused, 0 panics; peak {:.1} MB",
        f64::from(n) / secs,
        accepted.load(Ordering::Relaxed),
        refused.load(Ordering::Relaxed),
        worst.load(Ordering::Relaxed) as f64 / 1e6
    );
}

const MB: usize = 1 << 20;

/// Readers of small text files: a few MB whatever the input says.
fn text_bound(len: usize) -> usize {
    64 * MB + 256 * len
}

/// TIFF: the decoding limit per page (and its f64 copy), or what deflate can expand the bytes
/// to (at most 1032:1).
fn image_bound(len: usize) -> usize {
    2 * lbdem::io::tiff::MAX_FRAME_BYTES + 8 * 1032 * len + 16 * MB
}

// ---------------------------------------------------------------------------------------------
// Seeds and targets.

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn read(p: &str) -> Vec<u8> {
    std::fs::read(repo(p)).unwrap_or_else(|e| panic!("seed {p}: {e}"))
}

/// A scratch directory for targets that read a file by path.
fn scratch() -> &'static Path {
    static DIR: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    // In memory where the system has it: the targets write a file per execution.
    let shm = Path::new("/dev/shm");
    DIR.get_or_init(|| match shm.is_dir() {
        true => tempfile::tempdir_in(shm).unwrap_or_else(|_| tempfile::tempdir().unwrap()),
        false => tempfile::tempdir().unwrap(),
    })
    .path()
}

fn write_scratch(name: &str, bytes: &[u8]) -> PathBuf {
    let p = scratch().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn tiff_seeds() -> Vec<Vec<u8>> {
    use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};
    let mut out = Vec::new();
    type Encoder<'a> = TiffEncoder<&'a mut std::io::Cursor<Vec<u8>>>;
    let enc = |f: &dyn Fn(&mut Encoder)| {
        let mut c = std::io::Cursor::new(Vec::new());
        let mut e = TiffEncoder::new(&mut c).unwrap();
        f(&mut e);
        c.into_inner()
    };
    let g8: Vec<u8> = (0..48).map(|i| (i * 5) as u8).collect();
    let g16: Vec<u16> = (0..48).map(|i| (i * 1000) as u16).collect();
    let f32s: Vec<f32> = (0..48)
        .map(|i| if i == 7 { f32::NAN } else { i as f32 / 48.0 })
        .collect();
    let f64s: Vec<f64> = (0..16).map(|i| i as f64 * 0.1).collect();
    out.push(enc(&|e| e.write_image::<colortype::Gray8>(8, 6, &g8).unwrap()));
    out.push({
        let mut c = std::io::Cursor::new(Vec::new());
        TiffEncoder::new(&mut c)
            .unwrap()
            .with_compression(Compression::Deflate(DeflateLevel::Fast))
            .write_image::<colortype::Gray16>(8, 6, &g16)
            .unwrap();
        c.into_inner()
    });
    out.push({
        let mut c = std::io::Cursor::new(Vec::new());
        TiffEncoder::new(&mut c)
            .unwrap()
            .with_compression(Compression::Lzw)
            .write_image::<colortype::Gray32Float>(8, 6, &f32s)
            .unwrap();
        c.into_inner()
    });
    out.push({
        let mut c = std::io::Cursor::new(Vec::new());
        TiffEncoder::new(&mut c)
            .unwrap()
            .with_compression(Compression::Packbits)
            .write_image::<colortype::Gray64Float>(4, 4, &f64s)
            .unwrap();
        c.into_inner()
    });
    out.push(enc(&|e| {
        e.write_image::<colortype::Gray16>(8, 6, &g16).unwrap();
        e.write_image::<colortype::Gray16>(8, 6, &g16).unwrap();
    }));
    out.push(enc(&|e| {
        e.write_image::<colortype::RGB8>(4, 4, &g8[..48]).unwrap()
    }));
    out
}

fn png_seeds() -> Vec<Vec<u8>> {
    use image::{DynamicImage, ImageFormat};
    let enc = |img: DynamicImage, f: ImageFormat| {
        let mut c = std::io::Cursor::new(Vec::new());
        img.write_to(&mut c, f).unwrap();
        c.into_inner()
    };
    let grey = image::GrayImage::from_fn(12, 10, |x, y| image::Luma([((x * 20 + y * 7) % 256) as u8]));
    let rgb = image::RgbImage::from_fn(12, 10, |x, y| image::Rgb([(x * 20) as u8, (y * 25) as u8, 128]));
    let g16 = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(8, 8, |x, y| {
        image::Luma([(x * 8000 + y) as u16])
    });
    let mut out = vec![
        enc(DynamicImage::ImageLuma8(grey.clone()), ImageFormat::Png),
        enc(DynamicImage::ImageRgb8(rgb.clone()), ImageFormat::Png),
        enc(DynamicImage::ImageLuma16(g16), ImageFormat::Png),
        enc(DynamicImage::ImageRgb8(rgb), ImageFormat::Jpeg),
        enc(DynamicImage::ImageLuma8(grey), ImageFormat::Tiff),
    ];
    out.extend(tiff_seeds().into_iter().take(3));
    out
}

/// The `.toml` files under `dir` of the repository (recursive, sorted), skipping `skip`.
fn tomls(dir: &str, skip: &[&str]) -> Vec<PathBuf> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "toml") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(&repo(dir), &mut out);
    out.retain(|p| !skip.iter().any(|s| p.to_string_lossy().contains(s)));
    out.sort();
    out
}

/// Every scene of the repository (the 3D extruder's and the Su cases' included), and the small
/// dry scene. The files they extend are copied beside the fuzzed copy, so that the mutations
/// reach the merged scene and its checks, not only the `extends` line.
fn scene_seeds() -> Vec<Vec<u8>> {
    scene_bases();
    let mut v: Vec<Vec<u8>> = tomls("scenes", &["assemblies"])
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    assert!(v.len() >= 40, "{} scenes", v.len());
    v.push(DRY.as_bytes().to_vec());
    v
}

/// A small complete dry scene (the overrides and checkpoint targets build on it).
const DRY: &str = r#"[domain]
lo = [0.0, 0.0]
hi = [0.004, 0.004]
[particles]
density = 2.6
[particles.generate]
count = 4
lo = [0.0, 0.0]
hi = [0.004, 0.004]
seed = 3
templates = [ { circles = [[0.0, 0.0, 3.0e-4], [2.5e-4, 0.0, 2.5e-4]] } ]
[[walls]]
box = [0.0, 0.0, 0.004, 0.004]
[contact]
law = "linear"
k_n = 1000.0
k_t = 500.0
damping = { ratio = 0.3 }
mu = 0.5
rolling = { k_r = 1.0e-5, mu_r = 0.1 }
[dem]
dt = 4.0e-6
skin = 5.0e-5
gravity = [0.0, -9.81]
[run]
steps = 3
"#;

fn load_scene(bytes: &[u8]) -> bool {
    let p = write_scratch("scene.toml", bytes);
    lbdem::scenes::schema::load(&p, &Default::default()).is_ok()
}

fn override_seeds() -> Vec<Vec<u8>> {
    [
        "run.steps=100",
        "contact.mu=0.3\ndem.dt=2e-6",
        "dem.gravity=[0.0, -9.81]",
        "output.series={ every = 10 }",
        "contact.rolling.k_r=1e-5",
        "run.threads=2\nparticles.generate.count=3",
        "contact.damping={ ratio = 0.5 }",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

fn apply_overrides(bytes: &[u8]) -> bool {
    let scene = scratch().join("base.toml");
    if !scene.exists() {
        std::fs::write(&scene, DRY).unwrap();
    }
    let sets: Vec<String> = String::from_utf8_lossy(bytes)
        .lines()
        .map(str::to_string)
        .collect();
    let mut params = toml::Value::Table(Default::default());
    if lbdem::registry::apply_overrides(&mut params, &["overrides"], &sets).is_err() {
        return false;
    }
    let over = params
        .get("overrides")
        .and_then(|o| o.as_table())
        .cloned()
        .unwrap_or_default();
    lbdem::scenes::schema::load(&scene, &over).is_ok()
}

fn pipeline_seeds() -> Vec<Vec<u8>> {
    tomls("pipelines", &[])
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect()
}

fn parse_pipeline(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let path = repo("pipelines/fuzzed.toml");
    let Ok(p) = lbdem::pipeline::schema::Pipeline::parse(text, &path) else {
        return false;
    };
    p.stages.iter().all(|s| {
        let ctx = StageContext::new(scratch().join("out"), s.name.clone(), p.root.clone());
        lbdem::registry::find(&s.kind)
            .and_then(|k| k.prepare(s.params.clone(), &ctx))
            .is_ok()
    })
}

fn params_seeds() -> Vec<Vec<u8>> {
    let quick = String::from_utf8(read("pipelines/quickstart.toml")).unwrap();
    let radiograph: String = quick
        .split("[stage.params]")
        .nth(1)
        .unwrap()
        .split("[[stage]]")
        .next()
        .unwrap()
        .replace("[[stage.params.profiles]]", "[[profiles]]");
    let mut out = vec![
        format!("radiograph\n{radiograph}").into_bytes(),
        [b"synth-radiograph\n".as_slice(), &read("data/synth-alcu/params.toml")].concat(),
        b"digitise\nimage = \"photo.jpg\"\npixel_size_m = 1e-4\ncontainer = { kind = \"auto-box\" }\nsmooth_px = 2.0\nmin_grain_area_px = 400\n".to_vec(),
        b"settling-study\nresolutions = [8, 12]\nmethods = [\"psm\", \"bounce-back\"]\nprecisions = [\"f64\", \"f32\"]\n".to_vec(),
        b"report\ntitle = \"t\"\n".to_vec(),
        b"simulate\nscene = \"scenes/dry-settle.toml\"\noverrides = { run = { steps = 10 } }\n".to_vec(),
    ];
    // Every stage kind the pipelines use, with the parameters they give it (two per kind), and
    // the assembly protocol's parameter files (`lbdem assemble`).
    let mut per_kind = std::collections::BTreeMap::<String, usize>::new();
    for p in tomls("pipelines", &[]) {
        let t: toml::Table = toml::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        for s in t.get("stage").and_then(|s| s.as_array()).into_iter().flatten() {
            let (Some(kind), Some(params)) = (s.get("kind").and_then(|k| k.as_str()), s.get("params")) else {
                continue;
            };
            let n = per_kind.entry(kind.to_string()).or_default();
            if *n < 2 {
                *n += 1;
                out.push(format!("{kind}\n{}", toml::to_string(params).unwrap()).into_bytes());
            }
        }
    }
    for p in tomls("scenes/su2020/assemblies", &[]) {
        out.push([b"assemble\n".as_slice(), &std::fs::read(&p).unwrap()].concat());
    }
    let kinds: std::collections::BTreeSet<&str> = lbdem::registry::STAGES.iter().map(|k| k.kind).collect();
    let seeded: std::collections::BTreeSet<&str> = out
        .iter()
        .filter_map(|s| std::str::from_utf8(s).ok()?.lines().next())
        .collect();
    assert!(
        kinds.is_subset(&seeded),
        "stage kinds without a seed: {:?}",
        kinds.difference(&seeded)
    );
    out
}

fn prepare_params(bytes: &[u8]) -> bool {
    let text = String::from_utf8_lossy(bytes);
    let (kind, body) = text.split_once('\n').unwrap_or((&text, ""));
    let Ok(v) = toml::from_str::<toml::Table>(body) else {
        return false;
    };
    let ctx = StageContext::new(scratch().join("out"), kind.into(), repo(""));
    lbdem::registry::find(kind)
        .and_then(|k| k.prepare(toml::Value::Table(v), &ctx))
        .is_ok()
}

fn particle_seeds() -> Vec<Vec<u8>> {
    vec![
        b"grain_id,x,y,r\n0,0.001,0.002,3e-4\n0,0.0013,0.002,2.5e-4\n1,0.003,0.002,3e-4\n".to_vec(),
        b"# a comment\nx,y,r,grain_id,extra\n0.001,0.001,2e-4,5,a\n\n0.002,0.002,2e-4,6,b\n".to_vec(),
        b"body,circle,tag,x,y,r\n0,0,0,0.001,0.001,2e-4\n1,1,1,0.002,0.002,2e-4\n".to_vec(),
    ]
}

fn read_particles_csv(bytes: &[u8]) -> bool {
    let p = write_scratch("grains.csv", bytes);
    lbdem::scenes::build::particles_csv::read_csv_in(&p, 2.6, Some(([0.0, 0.0], [0.004, 0.004]))).is_ok()
}

fn header_seeds() -> Vec<Vec<u8>> {
    vec![
        br#"{"units": "px", "pixel_size": 1e-5}"#.to_vec(),
        br#"{"units": "m"}"#.to_vec(),
        b"{}".to_vec(),
    ]
}

fn read_particles_header(bytes: &[u8]) -> bool {
    let csv = "grain_id,x,y,r\n0,100,200,30\n1,300,200,30\n";
    let Ok(json) = std::str::from_utf8(bytes) else {
        return false;
    };
    lbdem::scenes::build::particles_csv::parse(csv, Some(json), Path::new("grains.csv")).is_ok()
}

fn snapshot_seeds() -> Vec<Vec<u8>> {
    vec![
        b"body,circle,tag,x,y,r,body_x,body_y,angle,vx,vy,omega,fx,fy,torque\n\
          0,0,0,0.001,0.002,0.0003,0.001,0.002,0.0,0.0,-0.01,0.0,0.0,-0.001,0.0\n\
          0,1,0,0.00125,0.002,0.00025,0.001,0.002,0.0,0.0,-0.01,0.0,0.0,-0.001,0.0\n\
          1,2,1,0.003,0.002,0.0003,0.003,0.002,0.5,0.0,0.0,1.5,0.0,0.0,1e-9\n"
            .to_vec(),
        b"i,j,body_i,body_j,fx,fy\n0,2,0,1,0.001,-0.002\n1,2,0,1,1e-5,3e-6\n".to_vec(),
        b"i,j,k,x,y,z,ux,uy,uz,pressure,solid_fraction\n0,0,0,0.5,0.5,0.0,0.1,0.0,0.0,1.5,0.0\n\
          1,0,0,1.5,0.5,0.0,0.2,NaN,0.0,-2.0,0.5\n0,1,0,0.5,1.5,0.0,0.0,0.0,0.0,0.0,1.0\n1,1,0,1.5,1.5,0.0,NaN,NaN,NaN,NaN,1.0\n"
            .to_vec(),
        b"i,j,k,x,y,z,ux,uy,uz,pressure\n0,0,0,0.5,0.5,0.0,0.1,0.0,0.0,1.5\n".to_vec(),
    ]
}

fn read_snapshots(bytes: &[u8]) -> bool {
    use lbdem::scenes::snapshot::{read_contacts, read_fluid, read_particles};
    let p = write_scratch("snapshot.csv", bytes);
    let a = read_particles(&p).is_ok();
    let b = read_contacts(&p).is_ok();
    let c = read_fluid(&p).is_ok();
    a || b || c
}

fn initial_fluid_seeds() -> Vec<Vec<u8>> {
    let mut t = String::from("i,j,k,x,y,z,ux,uy,uz,pressure\n");
    for j in 0..4 {
        for i in 0..4 {
            t.push_str(&format!("{i},{j},0,0,0,0,0.01,-0.02,0,{}\n", i as f64 - 1.5));
        }
    }
    vec![t.into_bytes()]
}

/// `[fluid] initial` on a 4 x 4 lattice with one solid node: the table's checks.
fn read_initial_fluid(bytes: &[u8]) -> bool {
    use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
    let p = write_scratch("initial.csv", bytes);
    let units =
        LatticeUnits::derive(&LatticeInput::new(0.01, 1e-3, 1000.0, 0.1, TimeSpec::Tau(0.8))).unwrap();
    let mut kind = vec![lbdem_lbm::domain::FLUID; 16];
    kind[5] = lbdem_lbm::domain::SOLID;
    lbdem::scenes::build::initial_fluid::read(&p, [4, 4, 1], 2, &kind, &units, 0.1).is_ok()
}

/// A small liquid-only scene: a 12 x 10 lid-driven box.
const FLUID: &str = r#"[lattice]
collision = "trt"
dx = 0.1
tau = 0.8
[domain]
lo = [0.0, 0.0]
hi = [1.2, 1.0]
[fluid]
density = 1000.0
viscosity = 0.01
u_max = 0.05
[boundaries]
y_max = { type = "wall", velocity = [0.05, 0.0] }
[run]
steps = 4
"#;

/// A small coupled scene: four buoyant grains in a 12 x 12 PSM lattice.
const COUPLED: &str = r#"[domain]
lo = [0.0, 0.0]
hi = [0.0012, 0.0012]
[particles]
density = 2.55
[particles.generate]
count = 4
lo = [0.0, 0.0]
hi = [0.0012, 0.0012]
seed = 5
templates = [ { circles = [[0.0, 0.0, 1.3e-4], [1.1e-4, 0.0, 1.1e-4]] } ]
[[walls]]
box = [0.0, 0.0, 0.0012, 0.0012]
[contact]
law = "linear"
k_n = 1.0e4
k_t = 5.0e3
damping = { ratio = 0.3 }
mu = 0.4
[dem]
dt = 1.4e-6
skin = 2.0e-5
gravity = [0.0, -9.81]
gravity_factor = -0.12
[fluid]
density = 2856.0
dynamic_viscosity = 1.82e-3
u_max = 0.02
[lattice]
collision = "bgk"
dx = 1.0e-4
dt = 5.6e-5
[coupling]
method = "psm"
r_hd = 0.8
depth = 1.0e-3
[run]
steps = 4
"#;

/// A small 3D extruder (Ness et al. 2017's model, barrel 8 d, die 4 d) from case A's file.
const EXTRUDER: &str = r#"[scene]
extends = "case-a.toml"
[extruder]
barrel_width = 8.0e-5
barrel_length = 6.0e-5
die_width = 4.0e-5
die_length = 4.0e-5
inlet_length = 3.0e-5
prefill_phi = 0.2
[run]
time = 1.0e-6   # case A gives time, so no steps
"#;

/// The files the repository's scenes extend, copied once into the scratch directory (seeds are
/// made on the test threads side by side, before `fuzz` serialises the targets).
fn scene_bases() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        for base in ["scenes/ness2017/case-a.toml", "scenes/su2020/shear-base.toml"] {
            let name = Path::new(base).file_name().unwrap();
            std::fs::write(scratch().join(name), read(base)).unwrap();
        }
    });
}

/// A scene as a model, ready to restore a checkpoint into (the files scenes extend beside it).
fn model(name: &str, scene: &str) -> Box<dyn lbdem::scenes::timeloop::Model> {
    let p = scratch().join(format!("model-{name}.toml"));
    scene_bases();
    if !p.exists() {
        std::fs::write(&p, scene).unwrap();
    }
    let l = lbdem::scenes::schema::load(&p, &Default::default()).unwrap();
    lbdem::scenes::run::model(&l, true).unwrap()
}

/// The model's state fresh and after four steps (even: the AA kernel exports only then).
fn checkpoint_seeds_of(name: &str, scene: &str) -> Vec<Vec<u8>> {
    let mut m = model(name, scene);
    let fresh = serde_json::to_vec(&m.save().unwrap()).unwrap();
    for _ in 0..4 {
        m.step(false).unwrap();
    }
    vec![fresh, serde_json::to_vec(&m.save().unwrap()).unwrap()]
}

/// A checkpoint's model state restored into a fresh model, then two steps: restoring refuses
/// what it cannot use instead of leaving a state that panics later.
fn restore_into(name: &str, scene: &str, bytes: &[u8]) -> bool {
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(bytes) else {
        return false;
    };
    let mut m = model(name, scene);
    if m.restore(v).is_err() {
        return false;
    }
    (0..2).all(|_| m.step(false).is_ok())
}

fn assembly_header_seeds() -> Vec<Vec<u8>> {
    vec![read("scenes/su2020/assemblies/reduced/assembly.json")]
}

/// The assembly header beside a fixed, valid assembly CSV (the reduced cell's).
fn read_assembly_header(bytes: &[u8]) -> bool {
    let csv = write_scratch(
        "assembly.csv",
        &read("scenes/su2020/assemblies/reduced/assembly.csv"),
    );
    write_scratch("assembly.json", bytes);
    let expect = lbdem::scenes::build::assembly_file::Expect {
        grains: 300,
        d: None,
        from: "fuzz",
    };
    lbdem::scenes::build::assembly_file::read_assembly(&csv, 0.52, &expect).is_ok()
}

fn sweep_seeds() -> Vec<Vec<u8>> {
    [
        "sweeps/su2020-ci.toml",
        "sweeps/su2020-matrix.toml",
        "sweeps/su2020-reduced-replicas.toml",
    ]
    .iter()
    .map(|p| read(p))
    .collect()
}

fn parse_sweep(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    lbdem::sweep::schema::Sweep::parse(text, &repo("sweeps/fuzz.toml")).is_ok()
}

/// The watchdog: a harness whose target stops returning fails, names itself and leaves the input
/// that hung (run as a child process, since the watchdog ends the process it runs in).
#[test]
fn a_hanging_execution_fails_the_harness_and_leaves_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("hang.bin");
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--ignored", "--exact", "hang_probe", "--nocapture"])
        .env("LBDEM_FUZZ_TIMEOUT_S", "0.5")
        .env("LBDEM_FUZZ_DUMP", &dump)
        .env("LBDEM_FUZZ_EXECS", "10")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(101),
        "the probe should end with the watchdog's failure: {err}"
    );
    assert!(
        err.contains("fuzz hang_probe: one execution has run for more than 0.5 s"),
        "the report should name the harness and the bound: {err}"
    );
    let kept = std::fs::read(&dump).expect("the input that hung should be kept");
    assert!(
        err.contains(&format!("its {}-byte input is in", kept.len())),
        "{err}"
    );
}

/// A target that hangs on its first mutated input; run only by the test above.
#[test]
#[ignore = "a child of a_hanging_execution_fails_the_harness_and_leaves_its_input"]
fn hang_probe() {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    fuzz(
        "hang_probe",
        10,
        vec![b"seed".to_vec()],
        text_bound,
        &|_: &[u8]| {
            // The seed check is the first call and returns; every later call hangs.
            while CALLS.fetch_add(1, Ordering::Relaxed) > 0 {
                std::thread::sleep(Duration::from_secs(1));
            }
            true
        },
    );
}

macro_rules! targets {
    ($($name:ident: $ci:expr, $seeds:expr, $bound:expr, $target:expr;)+) => {
        $(
            #[test]
            fn $name() {
                fuzz(stringify!($name), $ci, $seeds, $bound, &$target);
            }
        )+
    };
}

// One line per reader: name, CI executions, seeds, memory bound, the call.
targets! {
    tiff: 100_000, tiff_seeds(), image_bound, |b: &[u8]| lbdem::io::tiff::read_pages_from(std::io::Cursor::new(b), "fuzz.tif").is_ok();
    image: 20_000, png_seeds(), image_bound, |b: &[u8]| lbdem::stages::digitise::load::load_bytes(b, "fuzz.png", Default::default()).is_ok();
    scene_toml: 20_000, scene_seeds(), text_bound, load_scene;
    set_overrides: 10_000, override_seeds(), text_bound, apply_overrides;
    pipeline_toml: 50_000, pipeline_seeds(), text_bound, parse_pipeline;
    stage_params: 50_000, params_seeds(), text_bound, prepare_params;
    particle_csv: 10_000, particle_seeds(), text_bound, read_particles_csv;
    particle_header_json: 100_000, header_seeds(), text_bound, read_particles_header;
    snapshot_tables: 2_000, snapshot_seeds(), text_bound, read_snapshots;
    checkpoint_json: 2_000, checkpoint_seeds_of("dry", DRY), text_bound, |b: &[u8]| restore_into("dry", DRY, b);
    checkpoint_fluid: 1_000, checkpoint_seeds_of("fluid", FLUID), text_bound, |b: &[u8]| restore_into("fluid", FLUID, b);
    checkpoint_coupled: 1_000, checkpoint_seeds_of("coupled", COUPLED), text_bound, |b: &[u8]| restore_into("coupled", COUPLED, b);
    checkpoint_extruder: 500, checkpoint_seeds_of("extruder", EXTRUDER), text_bound, |b: &[u8]| restore_into("extruder", EXTRUDER, b);
    fluid_initial: 5_000, initial_fluid_seeds(), text_bound, read_initial_fluid;
    assembly_header: 5_000, assembly_header_seeds(), text_bound, read_assembly_header;
    sweep_toml: 20_000, sweep_seeds(), text_bound, parse_sweep;
}
