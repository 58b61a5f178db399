//! What `bench dem` and `bench dem3d` share: running a LAMMPS peer script and reading its
//! "Loop time" line, and a table row measured against LAMMPS with the two codes alternating rep
//! by rep (so a change of machine load hits both), printed and recorded as JSON.

use super::median;
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// Run `scripts/<script>` with `args`: LAMMPS's (particle-steps/s, contacts per particle).
pub(super) fn run_script(script: &str, args: &[String]) -> Result<(f64, f64)> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts").join(script);
    let out = std::process::Command::new("bash")
        .arg(&script)
        .args(args)
        .output()
        .with_context(|| format!("cannot run {}", script.display()))?;
    if !out.status.success() {
        bail!(
            "{} failed: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    loop_rate(&String::from_utf8_lossy(&out.stdout))
}

/// (particle-steps/s, contacts per particle) from a LAMMPS run's output: the "Loop time of T on
/// P procs for S steps with N atoms" line and, before it, the last thermo line, whose fifth
/// column is the mean contacts per particle (both peer decks print "step atoms ke phi z ...").
pub(super) fn loop_rate(text: &str) -> Result<(f64, f64)> {
    let lines: Vec<&str> = text.lines().collect();
    let at = lines
        .iter()
        .rposition(|l| l.starts_with("Loop time"))
        .context("no 'Loop time' line from LAMMPS")?;
    let w: Vec<&str> = lines[at].split_whitespace().collect();
    let field = |k: usize| -> Result<f64> {
        w.get(k)
            .and_then(|v| v.parse().ok())
            .with_context(|| format!("unreadable LAMMPS line '{}'", lines[at]))
    };
    let (t, s, n) = (field(3)?, field(8)?, field(11)?);
    let z = at
        .checked_sub(1)
        .and_then(|k| lines[k].split_whitespace().nth(4))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    Ok((n * s / t, z))
}

/// The 1-minute load average (the machine is shared: figures taken under load are depressed).
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Print the table's header.
pub(super) fn header(reps: usize) {
    println!(
        "| case | N | threads | lbdem M p-steps/s (median of {reps}) | z | LAMMPS M p-steps/s | LAMMPS z | ratio | load avg |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
}

/// One case on `threads` threads: `ours` and, if `peer`, `theirs` (each giving particle-steps/s
/// and contacts per particle) alternating for `reps` reps; the row printed with rates to
/// `digits` decimals and returned for the JSON file.
#[allow(clippy::too_many_arguments)]
pub(super) fn row(
    name: &str,
    n: usize,
    threads: usize,
    reps: usize,
    peer: bool,
    digits: usize,
    mut ours: impl FnMut() -> Result<(f64, f64)>,
    mut theirs: impl FnMut() -> Result<(f64, f64)>,
) -> Result<serde_json::Value> {
    let (mut rates, mut pr) = (Vec::new(), Vec::new());
    let (mut z, mut zl) = (0.0, f64::NAN);
    for _ in 0..reps {
        let (r, zz) = ours()?;
        rates.push(r);
        z = zz;
        if peer {
            let (r, zz) = theirs()?;
            pr.push(r);
            zl = zz;
        }
    }
    let rate = median(&rates);
    let (lammps, zl, ratio) = if peer {
        let t = median(&pr);
        (Some(t), Some(zl), Some(rate / t))
    } else {
        (None, None, None)
    };
    println!(
        "| {name} | {n} | {threads} | {:.digits$} | {z:.2} | {} | {} | {} | {} |",
        rate / 1e6,
        lammps.map_or("-".into(), |t| format!("{:.digits$}", t / 1e6)),
        zl.map_or("-".into(), |z| format!("{z:.2}")),
        ratio.map_or("-".into(), |r| format!("{r:.2}")),
        load_average().map_or("-".into(), |l| format!("{l:.1}"))
    );
    Ok(serde_json::json!({
        "case": name, "n": n, "threads": threads, "rate": rate, "rates": rates,
        "contacts_per_particle": z, "lammps_rate": lammps, "lammps_rates": pr,
        "lammps_contacts_per_particle": zl, "ratio_to_lammps": ratio, "load_average": load_average(),
    }))
}

/// Write the rows as `{"bench": bench, "rows": [...]}` to `path`, if given.
pub(super) fn write_json(path: Option<&PathBuf>, bench: &str, rows: Vec<serde_json::Value>) -> Result<()> {
    let Some(path) = path else {
        return Ok(());
    };
    let text = serde_json::to_string_pretty(&serde_json::json!({ "bench": bench, "rows": rows }))?;
    lbdem_core::atomic::write_atomic(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lammps_loop_line_gives_particle_steps_per_second_and_contacts() {
        let out = "   1200   10648   1.2e-09   0.62   5.01   33.1   0.2\n\
                   Loop time of 1.8436 on 1 procs for 1000 steps with 10648 atoms\n";
        let (rate, z) = loop_rate(out).unwrap();
        assert!((rate - 10648.0 * 1000.0 / 1.8436).abs() < 1e-6 * rate);
        assert_eq!(z, 5.01);
        let err = loop_rate("ERROR: Unknown pair style\n").unwrap_err();
        assert!(err.to_string().contains("Loop time"), "{err}");
    }
}
