//! Initial conditions of the grains (`[particles] velocity`, `omega`): a grain in free flight
//! moves as x0 + v t and turns as ω t, and a grain launched at a wall rebounds with the
//! restitution of its contact law; contradictory or malformed initial conditions are refused.

use super::*;
use crate::scenes::snapshot::read_particles;

/// One disk of radius 1 mm at (5, 5) mm in a 10 mm box, no gravity, launched with `extra`.
fn scene(extra: &str, steps: u64, zeta: f64) -> String {
    format!(
        r#"
[domain]
lo = [0.0, 0.0]
hi = [0.01, 0.01]
[particles]
density = 2.6
csv = "grains.csv"
{extra}
[[walls]]
box = [0.0, 0.0, 0.01, 0.01]
[contact]
law = "linear"
k_n = 1000.0
k_t = 500.0
damping = {{ ratio = {zeta} }}
mu = 0.0
clip = false
[dem]
dt = 1.0e-6
skin = 1.0e-4
[run]
steps = {steps}
[output]
series = {{ every = 10 }}
snapshots = {{ count = 1 }}
"#
    )
}

fn run(text: &str) -> (crate::scenes::snapshot::ParticleTable, tempfile::TempDir) {
    let t = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(t.path().join("scene")).unwrap();
    std::fs::write(
        t.path().join("scene/grains.csv"),
        "grain_id,x,y,r\n0,0.005,0.005,0.001\n",
    )
    .unwrap();
    let rec = simulate(text, t.path(), false).unwrap();
    let steps = rec.output.summary["steps"].as_u64().unwrap();
    let p = read_particles(&t.path().join(format!("out/snapshots/particles_{steps:09}.csv"))).unwrap();
    (p, t)
}

#[test]
fn a_launched_grain_flies_as_x0_plus_v_t_and_turns_as_omega_t() {
    // 2000 steps of 1 us: 2 ms at 0.5 m/s is 1 mm, short of the wall 4 mm away.
    let (p, _t) = run(&scene("velocity = [0.5, -0.25]\nomega = 30.0", 2000, 0.3));
    let t = 2000.0 * 1e-6;
    // Free flight: the leapfrog is exact for constant velocity (differences are rounding).
    assert!((p.body_x[0] - (0.005 + 0.5 * t)).abs() < 1e-15, "{}", p.body_x[0]);
    assert!(
        (p.body_y[0] - (0.005 - 0.25 * t)).abs() < 1e-15,
        "{}",
        p.body_y[0]
    );
    assert!((p.angle[0] - 30.0 * t).abs() < 1e-13, "{}", p.angle[0]);
    assert_eq!((p.vx[0], p.vy[0], p.omega[0]), (0.5, -0.25, 30.0));
}

#[test]
fn a_grain_launched_at_a_wall_rebounds_with_the_laws_restitution() {
    // 1 m/s toward the right wall (4 mm away): contact after 4 ms, lasting π sqrt(m/k) ≈ 0.9 ms;
    // 8 ms in all. Linear spring-dashpot without clipping (`clip = false`, the law's analytic
    // case): e = exp(−π ζ / sqrt(1 − ζ²)) (ζ = 0.2: 0.5266).
    let zeta: f64 = 0.2;
    let (p, _t) = run(&scene("velocity = [1.0, 0.0]", 8000, zeta));
    let e = (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    let got = -p.vx[0];
    eprintln!(
        "rebound {got} m/s, analytic restitution {e}, error {:.2e}",
        (got - e).abs() / e
    );
    assert!(p.vy[0].abs() < 1e-12, "{}", p.vy[0]);
    // Measured 1.39e-3 (the time step, 900 steps per contact); twice that.
    assert!((got - e).abs() / e < 2.8e-3, "rebound {got} vs e = {e}");
}

#[test]
fn an_initial_velocity_is_refused_with_a_compression_or_when_malformed() {
    let t = tempfile::tempdir().unwrap();
    let text = scene("velocity = [1.0, 0.0, 0.0]", 10, 0.3);
    let e = format!("{:#}", simulate(&text, t.path(), false).unwrap_err());
    assert!(e.contains("[particles] velocity has 3 numbers"), "{e}");
    let text = format!(
        "{}\n[compress]\ntarget_stress = 1.0\nv_max = 0.1\nv_threshold = 1e-4\nmax_steps = 10\n",
        scene("omega = 3.0", 10, 0.3)
    );
    let e = format!("{:#}", simulate(&text, t.path(), false).unwrap_err());
    assert!(e.contains("[compress]") && e.contains("omega"), "{e}");
    assert!(!t.path().join("out").exists());
}
