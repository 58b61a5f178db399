//! The drafting-kissing-tumbling case of Uhlmann (2005) as CSV on stdout, for plotting against
//! the digitised curves in `tests/data/`:
//! `cargo run --release -p lbdem-coupling --example dkt --features probes -- [CELLS_PER_DIAMETER] [U_LATTICE] [CONTACT_RANGE_CELLS]`
//! (`DKT_NO_CORRECTION=1` switches the interior-liquid correction off).

use lbdem_coupling::cases::dkt::{DktSpec, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cells: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(16);
    let u: f64 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(0.15);
    let mut spec = DktSpec {
        cells_per_diameter: cells,
        ..DktSpec::default()
    };
    if let Some(z) = args.next() {
        spec.contact_range_cells = z.parse()?;
    }
    if std::env::var("DKT_NO_CORRECTION").is_ok() {
        spec.interior_liquid_correction = false;
    }
    spec.tau = spec.tau_for(u);
    let r = run::<f64>(&spec)?;
    println!(
        "t_s,depth_trailing_m,depth_leading_m,lateral_trailing_m,lateral_leading_m,fall_speed_trailing_m_s,fall_speed_leading_m_s"
    );
    for s in &r.samples {
        println!(
            "{},{},{},{},{},{},{}",
            s.t, s.depth[0], s.depth[1], s.lateral[0], s.lateral[1], s.fall_speed[0], s.fall_speed[1]
        );
    }
    eprintln!(
        "{} cells/d, tau {:.4}: {} steps of {} nodes in {:.1} s",
        cells, spec.tau, r.lbm_steps, r.nodes, r.wall_seconds
    );
    Ok(())
}
