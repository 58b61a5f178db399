//! Value checks of a scene, on its TOML table before it is deserialised and before anything is
//! built or written: every number finite; each key's sign and range (a stiffness is positive, a
//! friction coefficient not negative, a packing fraction at most 1); vectors of the length the
//! key needs (`gravity = [gx, gy]`, not three numbers). A refused value is named with the file,
//! the line, the key, the value, the limit and the fix: the wrong value is reported as itself,
//! not later as "lower dt" from a run that blew up.
//!
//! Rules are data ([`RULES`]): a new key with a sign or a range is one line.

use anyhow::{Result, bail};
use std::path::Path;
use toml::Value;

/// What a key's value must be.
#[derive(Clone, Copy, Debug)]
enum Need {
    /// > 0.
    Positive,
    /// >= 0.
    NonNegative,
    /// In (0, 1].
    OpenFraction,
    /// In [0, 1).
    BelowOne,
    /// Strictly between the two.
    Between(f64, f64),
    /// An array of exactly this many numbers.
    Len(usize),
}

impl Need {
    fn holds(self, x: f64) -> bool {
        match self {
            Need::Positive => x > 0.0,
            Need::NonNegative => x >= 0.0,
            Need::OpenFraction => x > 0.0 && x <= 1.0,
            Need::BelowOne => (0.0..1.0).contains(&x),
            Need::Between(lo, hi) => x > lo && x < hi,
            Need::Len(_) => true,
        }
    }
    fn says(self) -> String {
        match self {
            Need::Positive => "must be above 0".into(),
            Need::NonNegative => "must not be negative".into(),
            Need::OpenFraction => "must lie in (0, 1]".into(),
            Need::BelowOne => "must lie in [0, 1)".into(),
            Need::Between(lo, hi) => format!("must lie strictly between {lo} and {hi}"),
            Need::Len(n) => format!("must be an array of {n} numbers"),
        }
    }
}

/// A rule: the key's dotted path (`*` = every entry of an array of tables), what it needs, and
/// what the key is (units, a typical value), for the message.
struct Rule(&'static str, Need, &'static str);

/// The contact laws' keys, checked under `[contact]` and `[wall_contact]` (docs/dem.md).
const LAW_RULES: &[Rule] = &[
    Rule("k_n", Need::Positive, "normal stiffness (N/m)"),
    Rule(
        "k_t",
        Need::NonNegative,
        "tangential stiffness (N/m; Su Table 1: k_n/2)",
    ),
    Rule("k_e", Need::Positive, "elastic normal stiffness (N/m)"),
    Rule("k_p", Need::NonNegative, "plastic normal stiffness (N/m)"),
    Rule("f_y", Need::Positive, "yield force (N)"),
    Rule("f_y.f_0", Need::Positive, "static yield force F_0 (N)"),
    Rule("f_y.rate", Need::NonNegative, "push-plate rate (m/s)"),
    Rule(
        "damping.ratio",
        Need::NonNegative,
        "damping ratio ζ (0 elastic, 1 critical)",
    ),
    Rule("damping.gamma", Need::NonNegative, "damping rate γ (1/s)"),
    Rule(
        "tangential_damping",
        Need::NonNegative,
        "tangential dashpot fraction (0.5)",
    ),
    Rule(
        "mu",
        Need::NonNegative,
        "Coulomb friction coefficient (Su Table 1: 0.3)",
    ),
    Rule("rolling.k_r", Need::Positive, "rolling stiffness (N m/rad)"),
    Rule(
        "rolling.mu_r",
        Need::NonNegative,
        "rolling friction coefficient (Su Table 1: 0.5)",
    ),
    Rule("young", Need::Positive, "Young's modulus (Pa)"),
    Rule("poisson", Need::Between(-1.0, 0.5), "Poisson's ratio"),
    Rule("a_damp", Need::NonNegative, "damping coefficient"),
    Rule("eta", Need::NonNegative, "damping coefficient"),
    Rule(
        "max_overlap",
        Need::Positive,
        "largest overlap as a fraction of the radius (0.05)",
    ),
];

/// Every other section's keys.
const RULES: &[Rule] = &[
    Rule("domain.lo", Need::Len(0), ""),
    Rule(
        "extruder.barrel_width",
        Need::Positive,
        "barrel width (m; Ness: 100 d)",
    ),
    Rule(
        "extruder.barrel_length",
        Need::Positive,
        "ram face to die entry (m; Ness: 300 d)",
    ),
    Rule("extruder.die_width", Need::Positive, "die width (m; Ness: 20 d)"),
    Rule("extruder.die_length", Need::Positive, "die length (m)"),
    Rule("extruder.depth", Need::Positive, "periodic depth (m; Ness: 5 d)"),
    Rule(
        "extruder.inlet_length",
        Need::Positive,
        "inlet box length (m; about 10 d)",
    ),
    Rule(
        "extruder.wall_diameter",
        Need::Positive,
        "wall-grain diameter (m; Ness: 0.5 d)",
    ),
    Rule("extruder.wall_spacing", Need::Positive, "wall-grain spacing (m)"),
    Rule(
        "extruder.body_force",
        Need::Positive,
        "body force per inlet grain (N)",
    ),
    Rule(
        "extruder.phi_inlet",
        Need::Between(0.0, 0.64),
        "inlet volume fraction (Ness: 0.5)",
    ),
    Rule(
        "extruder.steady_window",
        Need::Positive,
        "mass-balance window (s)",
    ),
    Rule(
        "extruder.steady_tolerance",
        Need::Between(0.0, 1.0),
        "relative rate difference (0.1)",
    ),
    Rule(
        "extruder.outlet_gap",
        Need::NonNegative,
        "removal distance past the die (m)",
    ),
    Rule(
        "suspension.diameters",
        Need::Len(2),
        "paste diameters [d, 1.5 d] (m)",
    ),
    Rule("suspension.diameters.*", Need::Positive, "paste diameter (m)"),
    Rule(
        "suspension.density",
        Need::Positive,
        "grain and liquid density (kg/m³)",
    ),
    Rule(
        "suspension.viscosity",
        Need::Positive,
        "liquid viscosity η_f (Pa s)",
    ),
    Rule("suspension.k_n", Need::Positive, "normal stiffness (N/m)"),
    Rule(
        "suspension.mu_p",
        Need::NonNegative,
        "particle-particle friction (Ness: 0.1 or 1)",
    ),
    Rule(
        "suspension.mu_w",
        Need::NonNegative,
        "particle-wall friction (Ness: 0 or 0.1)",
    ),
    Rule("suspension.dt", Need::Positive, "time step (s)"),
    Rule("suspension.skin", Need::NonNegative, "Verlet skin (m)"),
    Rule(
        "particles.density",
        Need::Positive,
        "density (kg/m² = ρ_S × depth)",
    ),
    Rule(
        "particles.area_factor",
        Need::OpenFraction,
        "factor on every grain's area (Su Float: 0.9)",
    ),
    Rule("particles.generate.count", Need::Positive, "number of grains"),
    Rule(
        "particles.velocity",
        Need::Len(2),
        "initial grain velocity [vx, vy] (m/s)",
    ),
    Rule("particles.generate.lo", Need::Len(2), "lower corner [x, y] (m)"),
    Rule("particles.generate.hi", Need::Len(2), "upper corner [x, y] (m)"),
    Rule(
        "particles.generate.templates.*.weight",
        Need::Positive,
        "template weight",
    ),
    Rule(
        "particles.generate.templates.*.circles.*",
        Need::Len(3),
        "circle [x, y, r] (m)",
    ),
    Rule("walls.*.box", Need::Len(4), "[x0, y0, x1, y1] (m)"),
    Rule("walls.*.p", Need::Len(2), "a point [x, y] of the plane (m)"),
    Rule("walls.*.n", Need::Len(2), "the plane's normal [nx, ny]"),
    Rule("walls.*.a", Need::Len(2), "segment end [x, y] (m)"),
    Rule("walls.*.b", Need::Len(2), "segment end [x, y] (m)"),
    Rule("walls.*.velocity", Need::Len(2), "wall velocity [vx, vy] (m/s)"),
    Rule("bonds.gap", Need::NonNegative, "bonding gap (m)"),
    Rule("bonds.params.k_n", Need::NonNegative, "bond normal stiffness"),
    Rule("bonds.params.k_s", Need::NonNegative, "bond shear stiffness"),
    Rule(
        "bonds.params.sigma_c",
        Need::NonNegative,
        "bond tensile strength (Pa)",
    ),
    Rule("bonds.params.cohesion", Need::NonNegative, "bond cohesion (Pa)"),
    Rule("bonds.params.lambda", Need::Positive, "bond radius multiplier"),
    Rule("bonds.params.damping", Need::BelowOne, "bond damping ratio ζ"),
    Rule("membrane.shell", Need::Positive, "membrane shell thickness (m)"),
    Rule(
        "membrane.threshold",
        Need::NonNegative,
        "outward movement before the push-back (m)",
    ),
    Rule("membrane.force", Need::NonNegative, "push-back force (N)"),
    Rule(
        "membrane.mass_scale",
        Need::Positive,
        "membrane mass scaling factor (1 = none)",
    ),
    Rule("dem.dt", Need::Positive, "DEM time step (s)"),
    Rule("dem.skin", Need::NonNegative, "Verlet-list skin (m)"),
    Rule("dem.gravity", Need::Len(2), "gravity [gx, gy] (m/s²)"),
    Rule(
        "dem.viscous_damping",
        Need::NonNegative,
        "viscous damping rate (1/s)",
    ),
    Rule("dem.local_damping", Need::BelowOne, "local (Cundall) damping"),
    Rule("dem.mass_scale", Need::Positive, "mass scaling factor (1 = none)"),
    Rule(
        "dem.mass_scale_control.inertial_number",
        Need::Between(0.0, 1.0),
        "largest scaled inertial number (Su Sect. 3.4: 0.002)",
    ),
    Rule(
        "dem.mass_scale_control.smallest",
        Need::Positive,
        "smallest mass scale (1 = the grains' own masses)",
    ),
    Rule(
        "dem.mass_scale_control.every",
        Need::Positive,
        "LBM steps between two choices of the mass scale",
    ),
    Rule("compress.target_stress", Need::Positive, "target 2D stress (N/m)"),
    Rule("compress.alpha", Need::Positive, "servo gain"),
    Rule("compress.v_max", Need::Positive, "largest wall speed (m/s)"),
    Rule("compress.tolerance", Need::Positive, "relative stress tolerance"),
    Rule(
        "compress.v_threshold",
        Need::Positive,
        "grain speed below which the assembly is at rest (m/s)",
    ),
    Rule(
        "compress.max_steps",
        Need::Positive,
        "step limit of the compression",
    ),
    Rule("compress.target_packing", Need::OpenFraction, "packing fraction"),
    Rule(
        "shear_cell.shear_length",
        Need::Positive,
        "shear length (m; Su: 0.01)",
    ),
    Rule(
        "shear_cell.membrane_relaxation",
        Need::OpenFraction,
        "weight of the membrane's newest velocity (default 0.5; 1 = none kept)",
    ),
    Rule(
        "shear_cell.settle",
        Need::NonNegative,
        "time with the plate held before it moves (s; 0 = none)",
    ),
    Rule(
        "shear_cell.settle_until_rest.speed",
        Need::Positive,
        "speed every grain must be below before the plate moves (m/s; Su: 1e-7)",
    ),
    Rule(
        "shear_cell.settle_until_rest.max_time",
        Need::Positive,
        "longest hold of the plate (s)",
    ),
    Rule("packed_zone.band", Need::Positive, "band thickness (m)"),
    Rule("packed_zone.slower_than", Need::Positive, "speed threshold (m/s)"),
    Rule("fluid.density", Need::Positive, "liquid density (kg/m³)"),
    Rule("fluid.viscosity", Need::Positive, "kinematic viscosity (m²/s)"),
    Rule(
        "fluid.dynamic_viscosity",
        Need::Positive,
        "dynamic viscosity (Pa s)",
    ),
    Rule(
        "fluid.u_max",
        Need::Positive,
        "largest liquid speed expected (m/s)",
    ),
    Rule("lattice.dx", Need::Positive, "node spacing (m)"),
    Rule("lattice.dt", Need::Positive, "LBM time step (s)"),
    Rule(
        "lattice.tau",
        Need::Positive,
        "relaxation time (lattice units, above 0.5)",
    ),
    Rule("lattice.magic", Need::Positive, "TRT magic parameter (0.25)"),
    Rule("lattice.mach_warn", Need::Positive, "Mach number that warns"),
    Rule("lattice.mach_max", Need::Positive, "Mach number that refuses"),
    Rule("obstacles.*.radius", Need::Positive, "obstacle radius (m)"),
    Rule(
        "coupling.r_hd",
        Need::OpenFraction,
        "hydrodynamic radius factor (0.8)",
    ),
    Rule("coupling.depth", Need::Positive, "sample depth (m)"),
    Rule(
        "coupling.remap_tolerance",
        Need::NonNegative,
        "grain displacement before it is mapped again (lattice cells, 0 = every move)",
    ),
    Rule("run.time", Need::Positive, "simulated time (s)"),
    Rule("run.until_slower_than", Need::Positive, "speed (m/s)"),
    Rule("run.until_slower_than.speed", Need::Positive, "speed (m/s)"),
    Rule("run.until_slower_than.over", Need::Positive, "window (s; Su: 10)"),
    Rule("run.until_steady", Need::Positive, "relative change"),
    Rule("run.until_wall_moved.distance", Need::Positive, "distance (m)"),
    Rule("run.wall_clock", Need::Positive, "wall-clock limit (s)"),
];

/// Check `table` (the scene as read, bases and overrides merged) against the rules; `path` and
/// `text` (the scene file's own text) name the file and the line in the message.
pub fn values(table: &toml::Table, path: &Path, text: &str, overrides: &toml::Table) -> Result<()> {
    let overridden = Value::Table(overrides.clone());
    let at = |keys: &[String]| -> String {
        let mut found = Vec::new();
        let pattern: Vec<&str> = keys.iter().map(String::as_str).collect();
        find(&overridden, &pattern, &mut Vec::new(), &mut found);
        match line_of(text, keys) {
            _ if !found.is_empty() => {
                format!("scene file {}, overridden (--set or overrides)", path.display())
            }
            Some(l) => format!("scene file {} line {l}", path.display()),
            None => format!("scene file {} (or the file it extends)", path.display()),
        }
    };
    let root = Value::Table(table.clone());
    if let Some((keys, x)) = first_non_finite(&root, &mut Vec::new()) {
        bail!(
            "{}: {} = {x:?}: every number must be finite; give a number (NaN and inf are not values)",
            at(&keys),
            dotted(&keys)
        );
    }
    let mut rules: Vec<(String, Need, &str)> = RULES
        .iter()
        .map(|Rule(p, n, w)| ((*p).to_string(), *n, *w))
        .collect();
    for section in ["contact", "wall_contact"] {
        rules.extend(
            LAW_RULES
                .iter()
                .map(|Rule(p, n, w)| (format!("{section}.{p}"), *n, *w)),
        );
    }
    for (pattern, need, what) in &rules {
        let pattern: Vec<&str> = pattern.split('.').collect();
        let mut found = Vec::new();
        find(&root, &pattern, &mut Vec::new(), &mut found);
        for (keys, v) in found {
            check_one(&keys, v, *need, what).map_err(|why| anyhow::anyhow!("{}: {why}", at(&keys)))?;
        }
    }
    Ok(())
}

fn check_one(keys: &[String], v: &Value, need: Need, what: &str) -> Result<(), String> {
    let name = dotted(keys);
    if let Need::Len(n) = need {
        let Some(a) = v.as_array() else {
            return Err(format!("{name} = {v}: {what} must be an array"));
        };
        // domain.lo: 2 or 3 numbers, checked with the physics.
        if n > 0 && a.len() != n {
            return Err(format!(
                "{name} has {} numbers: {what} {}; remove the extra or add the missing ones",
                a.len(),
                need.says()
            ));
        }
        return Ok(());
    }
    let x = match v {
        Value::Float(x) => *x,
        Value::Integer(i) => *i as f64,
        _ => return Ok(()), // the type is checked when the section is read
    };
    if need.holds(x) {
        return Ok(());
    }
    Err(format!(
        "{name} = {}: the {what} {}; correct the value",
        shown(v),
        need.says()
    ))
}

/// Every value at `pattern` below `v` (`*` matches each entry of an array), with its keys.
fn find<'a>(v: &'a Value, pattern: &[&str], keys: &mut Vec<String>, out: &mut Vec<(Vec<String>, &'a Value)>) {
    let Some((first, rest)) = pattern.split_first() else {
        out.push((keys.clone(), v));
        return;
    };
    if *first == "*" {
        for (i, item) in v.as_array().into_iter().flatten().enumerate() {
            keys.push(i.to_string());
            find(item, rest, keys, out);
            keys.pop();
        }
    } else if let Some(sub) = v.as_table().and_then(|t| t.get(*first)) {
        keys.push((*first).to_string());
        find(sub, rest, keys, out);
        keys.pop();
    }
}

/// The first NaN or infinite number below `v`, with its keys.
fn first_non_finite(v: &Value, trail: &mut Vec<String>) -> Option<(Vec<String>, f64)> {
    match v {
        Value::Float(x) if !x.is_finite() => Some((trail.clone(), *x)),
        Value::Table(t) => t.iter().find_map(|(k, v)| {
            trail.push(k.clone());
            let r = first_non_finite(v, trail);
            trail.pop();
            r
        }),
        Value::Array(a) => a.iter().enumerate().find_map(|(i, v)| {
            trail.push(i.to_string());
            let r = first_non_finite(v, trail);
            trail.pop();
            r
        }),
        _ => None,
    }
}

/// A value as a person writes it (4e-6, not 0.000004).
fn shown(v: &Value) -> String {
    match v {
        Value::Float(x) => format!("{x:?}"),
        v => v.to_string(),
    }
}

/// `[dem] gravity[1]`-style name of a key path.
fn dotted(keys: &[String]) -> String {
    let mut s = String::new();
    let mut section = true;
    for (k, key) in keys.iter().enumerate() {
        if key.parse::<usize>().is_ok() || (section && k == 0) {
            s.push_str(&format!("[{key}]"));
        } else {
            s.push_str(if section { " " } else { "." });
            s.push_str(key);
            section = false;
        }
    }
    s
}

/// The line (from 1) of the key at `keys` in `text`, if the file itself holds it (a key
/// inherited through `extends` or set by an override has none here).
pub fn line_of(text: &str, keys: &[String]) -> Option<usize> {
    use toml::de::{DeTable, DeValue};
    let root = DeTable::parse(text).ok()?;
    let mut span = root.span();
    let mut table: Option<&toml::de::DeTable> = Some(root.get_ref());
    let mut array: Option<&[toml::Spanned<DeValue>]> = None;
    for key in keys {
        let next = match (table, array) {
            (Some(t), _) => t
                .iter()
                .find(|(k, _)| k.get_ref() == key.as_str())
                .map(|(k, v)| (k.span(), v)),
            (None, Some(a)) => key
                .parse::<usize>()
                .ok()
                .and_then(|i| a.get(i))
                .map(|v| (v.span(), v)),
            _ => None,
        }?;
        span = next.0;
        (table, array) = match next.1.get_ref() {
            DeValue::Table(t) => (Some(t), None),
            DeValue::Array(a) => (None, Some(a.as_ref())),
            _ => (None, None),
        };
    }
    Some(text[..span.start.min(text.len())].matches('\n').count() + 1)
}

/// Checks across keys, on the parsed scene: what one key allows depends on another.
pub fn consistency(s: &super::Scene) -> Result<()> {
    if let Some(g) = s.particles.as_ref().and_then(|p| p.generate.as_ref()) {
        let (dlo, dhi) = (s.domain.lo2(), s.domain.hi2());
        for a in 0..2 {
            if g.lo[a] >= g.hi[a] {
                bail!(
                    "[particles.generate] lo = {:?}, hi = {:?}: on axis {a} lo must be below hi; swap them",
                    g.lo,
                    g.hi
                );
            }
            if g.lo[a] < dlo[a] || g.hi[a] > dhi[a] {
                bail!(
                    "[particles.generate] lo = {:?}, hi = {:?}: the generation box must lie inside [domain] \
                     (lo = {:?}, hi = {:?}); shrink it or enlarge the domain",
                    g.lo,
                    g.hi,
                    dlo,
                    dhi
                );
            }
        }
        if g.templates.is_empty() {
            bail!(
                "[particles.generate] templates = []: give at least one template of circles [[x, y, r], ...]"
            );
        }
        for (k, t) in g.templates.iter().enumerate() {
            if t.circles.is_empty() {
                bail!("[particles.generate] templates[{k}] has no circles; give one or more [x, y, r]");
            }
            if let Some(c) = t.circles.iter().find(|c| c[2] <= 0.0) {
                bail!(
                    "[particles.generate] templates[{k}] circle {c:?}: the radius r (third number) must be above 0"
                );
            }
        }
    }
    if let Some(p) = &s.particles
        && (p.velocity.is_some() || p.omega.is_some())
        && s.compress.is_some()
    {
        bail!(
            "[particles] velocity / omega and [compress]: the compression brings the grains to rest before \
             the run, so an initial velocity would be lost; remove one of them"
        );
    }
    if let Some(f) = &s.fluid
        && f.initial.is_some()
        && s.particles.is_some()
    {
        bail!(
            "[fluid] initial = {:?} in a scene with grains: an initial liquid field is read for liquid-only \
             scenes so far; remove it, or start the coupled run from rest",
            f.initial
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        );
    }
    if let Some(l) = &s.lattice
        && l.mach_warn > l.mach_max
    {
        bail!(
            "[lattice] mach_warn = {} is above mach_max = {}: the warning must come before the refusal; lower mach_warn",
            l.mach_warn,
            l.mach_max
        );
    }
    Ok(())
}
