//! The phases of the assembly protocol (Su et al. 2020 Sect. 2.4) as one resumable loop:
//! compression by servo walls, then either (fit to the sample, target packing fraction)
//! relaxation inside the sample's walls and the run's membrane and push-plate after it, or, in
//! Su's order (`[relax] inside = "membrane"`), the membrane and plate on the fitted sample,
//! relaxation under the run's law, and the target packing fraction inside the membrane; then the
//! F_0 measure. The state between chunks of steps is plain data (the DEM system and what was
//! recorded), checkpointed as JSON; a fresh stepper continues it to the same bits (the stepper's
//! results do not depend on when its list was built).

use super::Params;
use super::templates::{self, Template};
use crate::contract::{CHECKPOINT, Interrupted, StageContext};
use crate::scenes::build::dem as build;
use anyhow::{Context, Result, bail};
use lbdem_dem::assembly::{self as asm, PackingChange};
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::generate::{self, Compression};
use lbdem_dem::{Law, StepParams, Stepper, System, Vec2, Vector};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Steps between checks of the settling conditions, the clock and the progress bar.
const CHUNK: u64 = 200;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
enum Phase {
    Compress,
    Relax,
    RelaxInMembrane,
}

/// What the protocol did and measured (in `stage.json`'s summary and the checkpoint).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Record {
    /// Grains asked for (or found in the microstructure).
    pub requested: usize,
    pub source: String,
    pub compress_dt: f64,
    pub compress_steps: u64,
    /// Packing fraction and the largest relative wall-stress error when the servo settled.
    pub compressed_packing: f64,
    pub stress_error: f64,
    /// Scale factors (x, y) that fitted the compressed box to the sample.
    pub fit: (f64, f64),
    pub packing: Option<PackingChange>,
    pub relax_dt: f64,
    pub relax_steps: u64,
    pub max_speed: f64,
    /// Relaxed inside the membrane: the area of the polygon through the membrane grains'
    /// centroids when it went on (the sample was the box then), and the packing fraction the
    /// relaxation left, before the target was reached.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ring_area_0: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relaxed_packing: Option<f64>,
    pub packing_fraction: f64,
    pub f_0: f64,
    pub contacts: usize,
    pub membrane_grains: usize,
}

#[derive(Serialize, Deserialize)]
struct Checkpoint {
    key: String,
    phase: Phase,
    phase_steps: u64,
    record: Record,
    sys: System,
}

/// The finished assembly.
pub struct Done {
    pub sys: System,
    pub record: Record,
    pub templates: Vec<Template>,
}

/// The run's scene, as far as the assembly needs it.
struct Run {
    density: f64,
    /// The elastic parts of the run's laws (F_0's measure) and the laws themselves (the
    /// relaxation inside the membrane).
    law: Law,
    wall_law: Law,
    full_law: Law,
    full_wall_law: Law,
    walls: Vec<lbdem_dem::Wall>,
    membrane: Option<asm::MembraneSpec>,
    step: StepParams,
}

fn run_scene(p: &Params, ctx: &StageContext) -> Result<Run> {
    let path = ctx.resolve(&p.scene);
    let l = crate::scenes::schema::load(&path, &Default::default())
        .with_context(|| format!("the run's scene {} (key `scene`)", path.display()))?;
    let s = &l.scene;
    let pc = s.particles.as_ref().with_context(|| {
        format!(
            "{}: the run's scene has no [particles] (its density)",
            path.display()
        )
    })?;
    let law = s
        .contact
        .clone()
        .with_context(|| format!("{}: the run's scene has no [contact]", path.display()))?;
    let wall_law = s.wall_contact.clone().unwrap_or_else(|| law.clone());
    let step = s
        .dem
        .as_ref()
        .with_context(|| format!("{}: the run's scene has no [dem]", path.display()))?
        .step_params();
    Ok(Run {
        density: pc.density,
        law: elastic(law.clone()),
        wall_law: elastic(wall_law.clone()),
        full_law: law,
        full_wall_law: wall_law,
        walls: build::walls(s).with_context(|| format!("{}: [[walls]]", path.display()))?,
        membrane: build::membrane_spec(s),
        step,
    })
}

/// The elastic part of a law (Su Table 1: F_0 is measured before anything yields, and F_y is
/// set from it): the elastic-plastic law becomes the linear law with k_n = k_n,e.
fn elastic(l: Law) -> Law {
    match l {
        Law::Plastic(p) => Law::Linear(LinearSpringDashpot {
            k_n: p.k_e,
            k_t: p.k_t,
            damping: p.damping,
            tangential_damping: 0.5,
            mu: p.mu,
            rolling: p.rolling,
            clip: true,
        }),
        other => other,
    }
}

/// The templates and the bodies to compress, in their box.
fn start(p: &Params, ctx: &StageContext, density: f64) -> Result<(System, Vec<Template>, Record)> {
    let g = &p.grains;
    let (lo, hi) = (
        Vec2::new(p.sample.lo[0], p.sample.lo[1]),
        Vec2::new(p.sample.hi[0], p.sample.hi[1]),
    );
    let mut rec = Record::default();
    let (bodies, temps) = if let Some(m) = &g.microstructure {
        let path = ctx.resolve(m);
        let b = crate::scenes::build::particles_csv::read_csv(&path, density)
            .with_context(|| format!("[grains] microstructure = {}", path.display()))?;
        rec.source = format!("microstructure {}", m.display());
        (b, Vec::new())
    } else {
        let temps = match &g.templates {
            Some(t) => {
                rec.source = format!("templates {}", t.display());
                templates::from_csv(&ctx.resolve(t), g.d.map(|d| d[1]))?
            }
            None => {
                let d = g.d.context("[grains] d")?;
                rec.source = format!(
                    "{} templates of Table 2 sizes {:.0}:{:.0}:{:.0} um, aspect {}-{}",
                    g.n_templates,
                    d[0] * 1e6,
                    d[1] * 1e6,
                    d[2] * 1e6,
                    g.aspect[0],
                    g.aspect[1]
                );
                templates::from_sizes(d, g.aspect, g.n_templates, g.round_aspect)?
            }
        };
        let n = g.count.context("[grains] count")?;
        // A box of the sample's shape about its centre, large enough for the insertion packing.
        let area: f64 = n as f64
            * temps
                .iter()
                .map(|t| t.weight * t.shape.mass_props().map(|m| m.area).unwrap_or(0.0))
                .sum::<f64>();
        let s = (area / g.insert_packing / ((hi.x - lo.x) * (hi.y - lo.y))).sqrt();
        let c = (lo + hi) * 0.5;
        let half = (hi - lo) * (0.5 * s);
        let shapes: Vec<_> = temps.iter().map(|t| t.shape.clone()).collect();
        let w: Vec<f64> = temps.iter().map(|t| t.weight).collect();
        let b = generate::random_insert(&shapes, &w, density, c - half, c + half, n, g.seed)
            .context("random insertion of the grains")?;
        (b, temps)
    };
    rec.requested = bodies.len();
    // The compression box: around the grains, with a margin of one largest radius.
    let r_max = bodies.circle_r.iter().copied().fold(0.0, f64::max);
    let (mut blo, mut bhi) = (Vec2::new(f64::MAX, f64::MAX), Vec2::new(f64::MIN, f64::MIN));
    for c in 0..bodies.n_circles() {
        let q = bodies.circle_pos(c);
        blo = Vec2::new(
            blo.x.min(q.x - bodies.circle_r[c]),
            blo.y.min(q.y - bodies.circle_r[c]),
        );
        bhi = Vec2::new(
            bhi.x.max(q.x + bodies.circle_r[c]),
            bhi.y.max(q.y + bodies.circle_r[c]),
        );
    }
    let (blo, bhi) = (blo - Vec2::new(r_max, r_max), bhi + Vec2::new(r_max, r_max));
    let mut sys = System::new(bodies, lbdem_dem::Domain::open(blo, bhi));
    sys.walls = generate::box_walls(blo, bhi);
    Ok((sys, temps, rec))
}

/// Mean equivalent diameter and the compression's critical step and settings.
fn compression(p: &Params, sys: &System) -> (f64, StepParams, Compression) {
    let c = &p.compress;
    let d_mean = asm::size_stats(&sys.bodies).d_mean;
    let (crit, _, _) = Stepper::critical_time_step(sys, &c.contact, &c.contact);
    let mut sp = StepParams::new(c.dt_factor * crit, 0.1 * d_mean);
    sp.local_damping = c.local_damping;
    let comp = Compression {
        target_stress: c.target_stress,
        alpha: c.alpha,
        v_max: c.v_max * d_mean / crit,
        tolerance: c.tolerance,
        v_threshold: c.settle_speed * d_mean / crit,
        max_steps: c.max_steps,
    };
    (d_mean, sp, comp)
}

pub fn run(p: &Params, ctx: &StageContext) -> Result<Done> {
    let run = run_scene(p, ctx)?;
    if p.relax.inside == super::Inside::Membrane && run.membrane.is_none() {
        bail!(
            "[relax] inside = \"membrane\": the run's scene {} has no [membrane] to relax in; give it one or \
             relax inside the walls (inside = \"walls\")",
            ctx.resolve(&p.scene).display()
        );
    }
    let (sys0, temps, rec0) = start(p, ctx, run.density * p.compress.mass_scale)?;
    let ck_path = ctx.out_dir.join(CHECKPOINT);
    let (mut phase, mut phase_steps, mut rec, mut sys) = if ctx.resume {
        let bytes = std::fs::read(&ck_path).with_context(|| {
            format!(
                "--resume: no checkpoint {} (the run stopped before its first); run without --resume",
                ck_path.display()
            )
        })?;
        let ck: Checkpoint = serde_json::from_slice(&bytes).with_context(|| {
            format!(
                "checkpoint {} is damaged; run without --resume",
                ck_path.display()
            )
        })?;
        if ck.key != ctx.key {
            bail!(
                "checkpoint {} was made with other parameters, inputs or code; run without --resume",
                ck_path.display()
            );
        }
        (ck.phase, ck.phase_steps, ck.record, ck.sys)
    } else {
        (Phase::Compress, 0, rec0, sys0)
    };
    let clock = Instant::now();
    let mut log = Log::new();
    let mut last_ck = Instant::now();
    let save = |phase: Phase, phase_steps: u64, rec: &Record, sys: &System| -> Result<()> {
        let ck = Checkpoint {
            key: ctx.key.clone(),
            phase,
            phase_steps,
            record: rec.clone(),
            sys: sys.clone(),
        };
        lbdem_core::atomic::write_atomic(&ck_path, &serde_json::to_vec(&ck)?)
            .with_context(|| format!("cannot write checkpoint {}", ck_path.display()))
    };
    let mut stepper = Stepper::new();
    if phase == Phase::Compress {
        let (_, sp, comp) = compression(p, &sys);
        rec.compress_dt = sp.dt;
        // The servo's speed limits follow the gaps when it starts; a resumed compression keeps
        // the ones in the checkpoint (set again from today's gaps, they differ in the last bits).
        if phase_steps == 0 {
            generate::start_servo(&mut sys, &comp);
        }
        let pb = ctx.progress_bar(p.compress.max_steps, "compress");
        pb.set_position(phase_steps);
        loop {
            for _ in 0..CHUNK {
                stepper
                    .step(&sp, &p.compress.contact, &p.compress.contact, &mut sys)
                    .context("servo compression")?;
            }
            phase_steps += CHUNK;
            let (settled, err) = generate::servo_settled(&sys, &comp);
            pb.set_position(phase_steps);
            pb.set_message(format!(
                "compress: phi {:.3}, stress err {:.1e}",
                sys.packing_fraction(),
                err
            ));
            log.line(|| {
                format!(
                    "assemble: compress step {phase_steps}, packing {:.4}, wall stress error {:.1} %, fastest grain {:.2e} m/s",
                    sys.packing_fraction(),
                    100.0 * err,
                    sys.bodies.max_speed()
                )
            });
            if settled {
                rec.stress_error = err;
                break;
            }
            if phase_steps >= p.compress.max_steps {
                bail!(
                    "[compress]: the servo walls did not settle in max_steps = {} steps (wall stress {:.1} % from \
                     {} N/m, fastest grain {:.2e} m/s, limit {:.2e}); raise max_steps or alpha, or lower settle_speed",
                    p.compress.max_steps,
                    100.0 * err,
                    comp.target_stress,
                    sys.bodies.max_speed(),
                    comp.v_threshold
                );
            }
            interrupt_or_save(p, &clock, &mut last_ck, phase_steps, || {
                save(phase, phase_steps, &rec, &sys)
            })?;
        }
        pb.finish_and_clear();
        generate::stop_servo(&mut sys);
        rec.compress_steps = phase_steps;
        rec.compressed_packing = sys.packing_fraction();
        phase = match p.relax.inside {
            super::Inside::Walls => {
                prepare_relax(p, &run, &temps, &mut sys, &mut rec)?;
                Phase::Relax
            }
            super::Inside::Membrane => {
                membrane_on_box(p, &run, &mut sys, &mut rec)?;
                Phase::RelaxInMembrane
            }
        };
        phase_steps = 0;
        stepper = Stepper::new();
        save(phase, phase_steps, &rec, &sys)?;
        last_ck = Instant::now();
    }
    // Relaxation until every grain is slower than 1e-7 m/s (Su Sect. 2.4). Inside the walls
    // with the compression's law and step (the default), or inside the membrane under the
    // run's law and step. With the compression's law the membrane's bonds, 1e7 times softer
    // than the contacts, cannot hold the released overlaps and membrane grains fly off; with
    // Table 1's law the sample sheds the compression's overlaps by a creep (docs/su2020.md,
    // "Assemblies").
    let in_membrane = phase == Phase::RelaxInMembrane;
    let (law, wall_law) = if in_membrane {
        (&run.full_law, &run.full_wall_law)
    } else {
        (&p.compress.contact, &p.compress.contact)
    };
    let mut sp = if in_membrane {
        let mut sp = run.step;
        sp.gravity = Vec2::ZERO;
        sp
    } else {
        let (crit, _, _) = Stepper::critical_time_step(&sys, law, law);
        StepParams::new(p.compress.dt_factor * crit, rec_skin(&sys))
    };
    sp.local_damping = p.relax.local_damping;
    sp.viscous_damping = p.relax.viscous_damping.unwrap_or(1e-3 / sp.dt);
    rec.relax_dt = sp.dt;
    let pb = ctx.progress_bar(p.relax.max_steps, "relax");
    pb.set_position(phase_steps);
    loop {
        for _ in 0..CHUNK {
            stepper
                .step(&sp, law, wall_law, &mut sys)
                .context(if in_membrane {
                    "relaxation inside the membrane"
                } else {
                    "relaxation inside the sample's walls"
                })?;
        }
        phase_steps += CHUNK;
        let v = sys.bodies.max_speed();
        pb.set_position(phase_steps);
        pb.set_message(format!("relax: fastest grain {v:.2e} m/s"));
        log.line(|| format!("assemble: relax step {phase_steps}, {}", fastest(&sys)));
        if v < p.relax.threshold {
            break;
        }
        if phase_steps >= p.relax.max_steps {
            bail!(
                "[relax]: grains still move after max_steps = {} steps (threshold {:e} m/s; {}); raise \
                 max_steps or viscous_damping",
                p.relax.max_steps,
                p.relax.threshold,
                fastest(&sys)
            );
        }
        interrupt_or_save(p, &clock, &mut last_ck, phase_steps, || {
            save(phase, phase_steps, &rec, &sys)
        })?;
    }
    pb.finish_and_clear();
    rec.relax_steps = phase_steps;
    rec.max_speed = sys.bodies.max_speed();
    if in_membrane {
        // "Different initial 2D packing fractions were then generated from this sample".
        packing_in_membrane(p, &run, &temps, &mut sys, &mut rec)?;
    } else {
        let (lo, hi) = (
            Vec2::new(p.sample.lo[0], p.sample.lo[1]),
            Vec2::new(p.sample.hi[0], p.sample.hi[1]),
        );
        rec.packing_fraction = sys.bodies.total_area() / ((hi.x - lo.x) * (hi.y - lo.y));
        // The walls give way to the run's push-plate (held still) and membrane, at the run's
        // masses.
        run_boundaries(p, &run, &mut sys);
        match &run.membrane {
            Some(m) => asm::install_membrane(&mut sys, m),
            None => sys.membrane = None,
        }
    }
    rec.membrane_grains = sys.membrane.as_ref().map_or(0, |m| m.bodies.len());
    // F_0: the mean contact force of the run's elastic law on these overlaps (Table 1: U_0 =
    // F_0 / k_n,e), from one force evaluation at rest.
    at_rest(&mut sys);
    let mut probe = sys.clone();
    let mut measure = Stepper::new();
    let mut frozen = run.step;
    frozen.dt = 1e-6 * run.step.dt;
    frozen.gravity = Vec2::ZERO;
    measure
        .step_law(&frozen, &run.law, &run.wall_law, &mut probe)
        .context("the force evaluation that measures F_0")?;
    let (f0, n) = asm::mean_contact_force(&measure, &probe);
    rec.f_0 = f0;
    rec.contacts = n;
    sys.time = 0.0;
    sys.step = 0;
    let _ = std::fs::remove_file(&ck_path);
    Ok(Done {
        sys,
        record: rec,
        templates: temps,
    })
}

/// The sample's walls give way to the run's push-plate (held still) in an open domain, and the
/// grains take the run's masses.
fn run_boundaries(p: &Params, run: &Run, sys: &mut System) {
    let (lo, hi) = (
        Vec2::new(p.sample.lo[0], p.sample.lo[1]),
        Vec2::new(p.sample.hi[0], p.sample.hi[1]),
    );
    sys.walls = run
        .walls
        .iter()
        .map(|w| lbdem_dem::Wall::new(w.shape, lbdem_dem::WallMotion::Fixed))
        .collect();
    let margin = 0.1 * (hi - lo).norm();
    sys.domain = lbdem_dem::Domain::open(lo - Vec2::new(margin, margin), hi + Vec2::new(margin, margin));
    sys.bodies.scale_mass(1.0 / p.compress.mass_scale);
}

/// The area of the polygon through the membrane grains' centroids (Su Eq. 18's ring).
fn ring_area(sys: &System) -> Option<(f64, Vec<Vec2>)> {
    let m = sys.membrane.as_ref()?;
    let ring = m.polygon(&m.ring_order(), &sys.bodies);
    Some((lbdem_dem::polygon::signed_area(&ring).abs(), ring))
}

/// Su's order (Sect. 2.4): the compressed assembly fitted to the sample's box, the walls
/// replaced by the run's membrane and push-plate at once, the grains at the run's masses.
fn membrane_on_box(p: &Params, run: &Run, sys: &mut System, rec: &mut Record) -> Result<()> {
    let (lo, hi) = (
        Vec2::new(p.sample.lo[0], p.sample.lo[1]),
        Vec2::new(p.sample.hi[0], p.sample.hi[1]),
    );
    rec.fit = asm::fit_to_box(sys, lo, hi)?;
    // `run` refused a scene without one before anything ran.
    let m = run
        .membrane
        .as_ref()
        .context("the run's scene has no [membrane]")?;
    run_boundaries(p, run, sys);
    asm::install_membrane(sys, m);
    rec.ring_area_0 = ring_area(sys).map(|(a, _)| a);
    at_rest_from_zero(sys);
    Ok(())
}

/// The target packing fraction inside the relaxed membrane. The sample's area is the box's,
/// changed as the polygon through the membrane's centroids changed since it went on; grains
/// are scaled, deleted (never membrane grains) or added inside the ring, and the membrane is
/// made afresh on the same grains as they now lie.
fn packing_in_membrane(
    p: &Params,
    run: &Run,
    temps: &[Template],
    sys: &mut System,
    rec: &mut Record,
) -> Result<()> {
    let m = run
        .membrane
        .as_ref()
        .context("the run's scene has no [membrane]")?;
    let (a, ring) = ring_area(sys).context("the membrane went missing while relaxing")?;
    let a0 = rec.ring_area_0.context("the checkpoint has no membrane area")?;
    let box_area = (p.sample.hi[0] - p.sample.lo[0]) * (p.sample.hi[1] - p.sample.lo[1]);
    let area = box_area * a / a0;
    rec.relaxed_packing = Some(sys.bodies.total_area() / area);
    let (mut lo, mut hi) = (Vec2::new(f64::MAX, f64::MAX), Vec2::new(f64::MIN, f64::MIN));
    for q in &ring {
        lo = Vec2::new(lo.x.min(q.x), lo.y.min(q.y));
        hi = Vec2::new(hi.x.max(q.x), hi.y.max(q.y));
    }
    let sample = asm::Sample {
        lo,
        hi,
        area,
        ring: Some(&ring),
    };
    let change = asm::adjust_packing(
        sys,
        &sample,
        p.packing.target,
        p.packing.method,
        p.packing.max_size_change,
        &smallest(p, temps, rec, sys),
        run.density,
        p.grains.seed,
    )
    .with_context(|| format!("[packing] target = {}", p.packing.target))?;
    rec.packing = Some(change);
    rec.packing_fraction = change.to;
    let members: Vec<u32> = (0..sys.bodies.len() as u32)
        .filter(|&k| sys.bodies.tag[k as usize] == 1)
        .collect();
    asm::install_membrane_on(sys, members, m);
    Ok(())
}

/// The grain added in interstices (Su: "smaller grains"): the smallest template at
/// `small_grain` of its size, as fitted to the sample.
fn smallest(p: &Params, temps: &[Template], rec: &Record, sys: &System) -> lbdem_dem::ClumpShape<Vec2> {
    temps
        .iter()
        .min_by(|a, b| a.d_eq.total_cmp(&b.d_eq))
        .map(|t| {
            t.shape
                .scaled(p.packing.small_grain * (rec.fit.0 * rec.fit.1).sqrt())
        })
        .unwrap_or_else(|| lbdem_dem::ClumpShape::disk(0.25 * asm::size_stats(&sys.bodies).d_min))
}

/// Verlet-list skin: a tenth of the mean grain diameter.
fn rec_skin(sys: &System) -> f64 {
    0.1 * asm::size_stats(&sys.bodies).d_mean
}

/// After the compression: fit to the sample, reach the target packing fraction (walls kept,
/// fixed at the sample's box), grains at rest.
fn prepare_relax(
    p: &Params,
    run: &Run,
    temps: &[Template],
    sys: &mut System,
    rec: &mut Record,
) -> Result<()> {
    let (lo, hi) = (
        Vec2::new(p.sample.lo[0], p.sample.lo[1]),
        Vec2::new(p.sample.hi[0], p.sample.hi[1]),
    );
    rec.fit = asm::fit_to_box(sys, lo, hi)?;
    // "Different initial packing fractions were then generated from this sample" (Sect. 2.4).
    let change = asm::adjust_packing(
        sys,
        &asm::Sample::boxed(lo, hi),
        p.packing.target,
        p.packing.method,
        p.packing.max_size_change,
        &smallest(p, temps, rec, sys),
        run.density * p.compress.mass_scale,
        p.grains.seed,
    )
    .with_context(|| format!("[packing] target = {}", p.packing.target))?;
    rec.packing = Some(change);
    at_rest_from_zero(sys);
    Ok(())
}

/// Write a checkpoint every `checkpoint_seconds`, and stop with one after `wall_clock`.
fn interrupt_or_save(
    p: &Params,
    clock: &Instant,
    last: &mut Instant,
    step: u64,
    save: impl Fn() -> Result<()>,
) -> Result<()> {
    if let Some(limit) = p.wall_clock
        && clock.elapsed().as_secs_f64() >= limit
    {
        save()?;
        return Err(Interrupted {
            reason: format!("wall_clock = {limit} s reached"),
            step,
        }
        .into());
    }
    if last.elapsed().as_secs_f64() >= p.checkpoint_seconds {
        save()?;
        *last = Instant::now();
    }
    Ok(())
}

/// The fastest grain: its speed, index, whether it is a membrane grain, where it is.
fn fastest(sys: &System) -> String {
    let b = &sys.bodies;
    let k = (0..b.len())
        .max_by(|&i, &j| b.vel[i].norm2().total_cmp(&b.vel[j].norm2()))
        .unwrap_or(0);
    if b.is_empty() {
        return "no grains".into();
    }
    format!(
        "fastest grain {:.2e} m/s (#{k}{}, at {:.3}, {:.3} mm, spin {:.2e} rad/s)",
        b.vel[k].norm(),
        if b.tag[k] == 1 { ", membrane" } else { "" },
        b.pos[k].x * 1e3,
        b.pos[k].y * 1e3,
        b.omega[k]
    )
}

/// A status line every minute when stderr is not a terminal (logs of long runs, where the
/// progress bar is not drawn).
struct Log {
    on: bool,
    last: Instant,
}

impl Log {
    fn new() -> Self {
        use std::io::IsTerminal;
        Self {
            on: !std::io::stderr().is_terminal(),
            last: Instant::now(),
        }
    }
    fn line(&mut self, text: impl FnOnce() -> String) {
        if self.on && self.last.elapsed().as_secs() >= 60 {
            eprintln!("{}", text());
            self.last = Instant::now();
        }
    }
}

/// [`at_rest`], with the clock at zero: the start of a phase that steps.
fn at_rest_from_zero(sys: &mut System) {
    at_rest(sys);
    sys.time = 0.0;
    sys.step = 0;
}

/// Every grain stopped and the contact history cleared: the state the next phase of the
/// protocol (F_0's force evaluation, relaxation after a %PK change) starts from.
fn at_rest(sys: &mut System) {
    sys.bodies.vel.iter_mut().for_each(|v| *v = Vec2::ZERO);
    sys.bodies.omega.iter_mut().for_each(|w| *w = 0.0);
    sys.contacts = Default::default();
}
