//! Time of the edge flag (`lbdem_imaging::edge::Flagger`) on a 2048² field of 60 px disks
//! (window 120 px, REV 190 px: the `lbdem bench radiograph` geometry), median of 11:
//! `cargo run --release -p lbdem-imaging --example flag_timing --features probes`. The figure in `edge.rs`'s
//! documentation comes from here.
use lbdem_imaging::Roi;
use lbdem_imaging::edge::{BulkPhase, Flagger};
use lbdem_imaging::rev::Sat;
use lbdem_imaging::synth;
use ndarray::Array2;
use std::time::Instant;
fn main() {
    let n = 2048;
    let d = n as f64 / 34.0; // 60 px grains
    let disks = synth::pack_disks(Roi::new(0, n / 16, n, n - n / 8), d, 0.2, 0.45, 7).unwrap();
    let mut g = Array2::<f64>::zeros((n, n));
    for dk in &disks {
        let (x, y, r) = (dk.x, dk.y, dk.r);
        for row in ((y - r).max(0.0) as usize)..((y + r).min(n as f64 - 1.0) as usize) {
            for col in ((x - r).max(0.0) as usize)..((x + r).min(n as f64 - 1.0) as usize) {
                if (col as f64 + 0.5 - x).powi(2) + (row as f64 + 0.5 - y).powi(2) < r * r {
                    g[[row, col]] = 1.0;
                }
            }
        }
    }
    for r in 0..n / 16 {
        g.row_mut(r).fill(1.0);
    }
    let mut sat = Sat::new();
    sat.build(g.view());
    let rule = BulkPhase {
        window_px: 120,
        liquid_below: 0.05,
        solid_above: 0.95,
    };
    let mut ts = Vec::new();
    let mut f = Flagger::new(rule, 190).unwrap();
    for _ in 0..11 {
        let t = Instant::now();
        f.frame(&sat).unwrap();
        let a = t.elapsed().as_secs_f64();
        let near = f.near_u8();
        let b = t.elapsed().as_secs_f64();
        let tiles = f.tiles();
        let c = t.elapsed().as_secs_f64();
        std::hint::black_box((&near, &tiles));
        ts.push((a, b - a, c - b));
    }
    ts.sort_by(|x, y| (x.0 + x.1 + x.2).total_cmp(&(y.0 + y.1 + y.2)));
    let m = ts[ts.len() / 2];
    println!(
        "frame {:.2} ms, near_u8 {:.2} ms, tiles {:.2} ms (median of 11)",
        m.0 * 1e3,
        m.1 * 1e3,
        m.2 * 1e3
    );
    let near = f.near_u8();
    println!(
        "flagged share {:.3}",
        near.iter().filter(|&&v| v > 0).count() as f64 / near.len() as f64
    );
}
