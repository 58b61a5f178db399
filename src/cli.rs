//! The command line. `run` and `bench` are its own; every other subcommand is a stage kind of
//! [`crate::registry::STAGES`], run through the same staging path as a pipeline step
//! ([`crate::pipeline::run_alone`]: atomic outputs, manifest, provenance).

use crate::pipeline::{self, Invocation};
use crate::registry::{self, CliShape, StageKind};
use anyhow::{Context, Result};
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use std::path::{Path, PathBuf};

/// The `lbdem` command with one subcommand per stage kind.
pub fn command() -> Command {
    let mut cmd = Command::new("lbdem")
        .version(env!("CARGO_PKG_VERSION"))
        .about("Radiographs, grains and coupled LBM-DEM simulations of particle-laden liquids")
        .subcommand_required(true)
        .arg_required_else_help(true)
        .subcommand(
            Command::new("run")
                .about("Run a pipeline: an ordered list of stages in a TOML file")
                .arg(
                    Arg::new("pipeline")
                        .required(true)
                        .value_parser(clap::value_parser!(PathBuf))
                        .help("The pipeline file, e.g. pipelines/quickstart.toml"),
                )
                .arg(
                    Arg::new("force")
                        .long("force")
                        .action(ArgAction::SetTrue)
                        .help("Rerun every stage even when its inputs and parameters are unchanged"),
                )
                .arg(
                    Arg::new("lanes")
                        .long("lanes")
                        .value_parser(clap::value_parser!(u64).range(1..=256))
                        .default_value("1")
                        .help(
                            "Stages side by side, each once the stages it reads have finished, in a pool \
                             of its share of the cores (e.g. 2 on 2 cores for one-thread simulations)",
                        ),
                ),
        )
        .subcommand(sweep_command())
        .subcommand(crate::bench::BenchArgs::augment_args(
            Command::new("bench")
                .about("Benchmarks: print rates and their ratio to a reference measured in the same run"),
        ));
    for k in registry::STAGES {
        cmd = add_stage(cmd, k.cli, k);
    }
    cmd
}

/// `lbdem sweep SWEEP.toml [--out DIR] [--parallel N] [--threads N] [--force] [--list]`.
fn sweep_command() -> Command {
    let count = || clap::value_parser!(usize);
    Command::new("sweep")
        .about("Run a scene or pipeline over axes of parameters and random replicas; tables and a report of the results")
        .arg(
            Arg::new("sweep")
                .required(true)
                .value_parser(clap::value_parser!(PathBuf))
                .help("The sweep file, e.g. sweeps/su2020-ci.toml (docs/sweeps.md)"),
        )
        .arg(
            Arg::new("out")
                .long("out")
                .short('o')
                .value_parser(clap::value_parser!(PathBuf))
                .help("Output directory (default: the sweep file's `out`, else out/<name>)"),
        )
        .arg(
            Arg::new("parallel")
                .long("parallel")
                .value_parser(count())
                .help("Cases side by side (default: as many as cores / threads)"),
        )
        .arg(
            Arg::new("threads")
                .long("threads")
                .value_parser(count())
                .help("Threads per case (default: cores / parallel); parallel × threads ≤ cores"),
        )
        .arg(
            Arg::new("force")
                .long("force")
                .action(ArgAction::SetTrue)
                .help("Rerun every case even when it finished before with the same inputs"),
        )
        .arg(
            Arg::new("list")
                .long("list")
                .action(ArgAction::SetTrue)
                .help("Print the cases and their directories, and run nothing"),
        )
}

/// Add `kind` at `path` below `cmd`, creating the intermediate groups (`synth`).
fn add_stage(cmd: Command, path: &[&'static str], kind: &'static StageKind) -> Command {
    match path {
        [] => cmd,
        [leaf] => cmd.subcommand(stage_command(leaf, kind)),
        [group, rest @ ..] => {
            let group: &'static str = group;
            let exists = cmd.get_subcommands().any(|c| c.get_name() == group);
            let cmd = if exists {
                cmd
            } else {
                cmd.subcommand(
                    Command::new(group)
                        .about(format!("{group} stages"))
                        .subcommand_required(true),
                )
            };
            cmd.mut_subcommand(group, |g| add_stage(g, rest, kind))
        }
    }
}

fn stage_command(name: &'static str, kind: &'static StageKind) -> Command {
    let set = Arg::new("set")
        .long("set")
        .value_name("KEY=VALUE")
        .action(ArgAction::Append)
        .help(
            "Override a parameter: `--set key=value` (value parsed as TOML; dotted keys reach into tables)",
        );
    let c = Command::new(name).about(kind.about).arg(set);
    match kind.shape {
        CliShape::ParamsFile => c
            .arg(
                Arg::new("params")
                    .required(true)
                    .value_parser(clap::value_parser!(PathBuf))
                    .help("The stage's parameters (TOML, the same keys as in a pipeline's [stage.params])"),
            )
            .arg(
                Arg::new("out")
                    .long("out")
                    .short('o')
                    .default_value("out")
                    .value_parser(clap::value_parser!(PathBuf))
                    .help("Output directory"),
            ),
        CliShape::SceneFile => c
            .arg(
                Arg::new("scene")
                    .required(true)
                    .value_parser(clap::value_parser!(PathBuf))
                    .help("The scene file (sections [domain], [particles], [fluid], ...; docs/scenes.md)"),
            )
            .arg(
                Arg::new("out")
                    .long("out")
                    .short('o')
                    .value_parser(clap::value_parser!(PathBuf))
                    .help("Output directory (default: out/<scene name>)"),
            )
            .arg(
                Arg::new("resume")
                    .long("resume")
                    .action(ArgAction::SetTrue)
                    .help("Continue the interrupted run in the output directory from its checkpoint"),
            ),
    }
}

/// A refused run is a message for the user, not a crash: without this, RUST_BACKTRACE=1 (set in
/// many Rust developers' shells) makes anyhow capture and print a stack backtrace under every
/// refusal. Panics still follow RUST_BACKTRACE; RUST_LIB_BACKTRACE=1 brings the error backtraces
/// back for whoever wants them. Both binaries (`lbdem`, `lbdem-mpi`) call it first.
///
/// # Safety
/// Call it as the first statement of `main`, before the process has a second thread (it sets an
/// environment variable).
pub unsafe fn refusals_without_backtraces() {
    if std::env::var_os("RUST_LIB_BACKTRACE").is_none() {
        // SAFETY: the caller guarantees no other thread exists yet.
        unsafe { std::env::set_var("RUST_LIB_BACKTRACE", "0") };
    }
}

pub fn main() -> Result<()> {
    let m = command().get_matches();
    // A typo in LBDEM_ISA is refused before anything runs (the kernels would ignore it).
    if let Some(cap) = lbdem_core::simd::requested()?
        && lbdem_core::simd::NATIVE_V4
        && cap < lbdem_core::simd::Level::V4
    {
        eprintln!(
            "warning: {} = {} has no effect: this binary was built for the native CPU (x86-64-v4), every \
             function runs at that level; build without `-C target-cpu=native` (the default, portable build) to use the cap",
            lbdem_core::simd::ISA_ENV,
            cap.name()
        );
    }
    match m.subcommand() {
        Some(("run", a)) => {
            let path = a.get_one::<PathBuf>("pipeline").context("PIPELINE is required")?;
            let lanes = a.get_one::<u64>("lanes").copied().unwrap_or(1) as usize;
            pipeline::run_file(path, a.get_flag("force"), lanes)
        }
        Some(("sweep", a)) => {
            let file = a
                .get_one::<PathBuf>("sweep")
                .context("SWEEP is required")?
                .clone();
            crate::sweep::run(&crate::sweep::Args {
                file,
                out: a.get_one::<PathBuf>("out").cloned(),
                parallel: a.get_one::<usize>("parallel").copied(),
                threads: a.get_one::<usize>("threads").copied(),
                force: a.get_flag("force"),
                list: a.get_flag("list"),
            })
            .map(|_| ())
        }
        Some(("bench", a)) => crate::bench::run(&crate::bench::BenchArgs::from_arg_matches(a)?),
        Some((name, a)) => {
            let mut path = vec![name];
            let mut cur = a;
            while let Some((sub, sa)) = cur.subcommand() {
                path.push(sub);
                cur = sa;
            }
            let kind = registry::STAGES
                .iter()
                .find(|k| k.cli == path.as_slice())
                .with_context(|| format!("unknown command {}", path.join(" ")))?;
            pipeline::run_alone(kind, invocation(kind, cur)?)
        }
        None => unreachable!("clap requires a subcommand"),
    }
}

/// The stage's parameters, output directory and resume flag from its subcommand's arguments.
fn invocation(kind: &StageKind, a: &ArgMatches) -> Result<Invocation> {
    let sets: Vec<String> = a
        .get_many::<String>("set")
        .into_iter()
        .flatten()
        .cloned()
        .collect();
    match kind.shape {
        CliShape::ParamsFile => {
            let path = a.get_one::<PathBuf>("params").context("PARAMS is required")?;
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read parameter file {}", path.display()))?;
            let mut params: toml::Value =
                toml::from_str(&text).with_context(|| format!("{} is not valid TOML", path.display()))?;
            registry::apply_overrides(&mut params, &[], &sets)?;
            Ok(Invocation {
                params,
                out: a
                    .get_one::<PathBuf>("out")
                    .cloned()
                    .unwrap_or_else(|| "out".into()),
                base_dir: parent(path),
                resume: false,
            })
        }
        CliShape::SceneFile => {
            let path = a.get_one::<PathBuf>("scene").context("SCENE is required")?;
            let name = crate::scenes::schema::scene_name(path)?;
            let scene = path
                .file_name()
                .map(PathBuf::from)
                .unwrap_or_else(|| path.clone());
            let mut params = toml::Value::Table(toml::Table::from_iter([(
                "scene".to_string(),
                toml::Value::String(scene.to_string_lossy().into_owned()),
            )]));
            registry::apply_overrides(&mut params, &["overrides"], &sets)?;
            Ok(Invocation {
                params,
                out: a
                    .get_one::<PathBuf>("out")
                    .cloned()
                    .unwrap_or_else(|| PathBuf::from("out").join(name)),
                base_dir: parent(path),
                resume: a.get_flag("resume"),
            })
        }
    }
}

fn parent(p: &Path) -> PathBuf {
    p.parent().map(Path::to_path_buf).unwrap_or_default()
}
