//! Command-line definitions. Every stage is a subcommand of its own and also a pipeline
//! stage; both paths go through [`crate::stages::run_standalone`].

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "lbdem",
    version,
    about = "Radiographs, grains and coupled LBM-DEM simulations of particle-laden liquids"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a pipeline: an ordered list of stages in a TOML file.
    Run {
        /// The pipeline file, e.g. pipelines/quickstart.toml.
        pipeline: PathBuf,
        /// Rerun every stage even when its inputs and parameters are unchanged.
        #[arg(long)]
        force: bool,
    },
    /// Radiographs to thickness-corrected solid fraction, REV maps and volumetric strain.
    Radiograph(StageArgs),
    /// Make synthetic inputs with a known answer.
    #[command(subcommand)]
    Synth(SynthCommand),
    /// Segment grains in an image and fit two-circle clumps.
    Digitise(StageArgs),
    /// Run a scene (fluid, dry DEM or coupled) from its TOML file.
    Simulate(SimulateArgs),
    /// Assemble an HTML report from the outputs of earlier stages.
    Report(StageArgs),
    /// Benchmarks: print rates and their ratio to a reference measured in the same run.
    Bench(crate::bench::BenchArgs),
}

#[derive(Subcommand, Debug)]
pub enum SynthCommand {
    /// Forward Beer-Lambert radiographs of a disk assembly with known g_S and eps_vol.
    Radiograph(StageArgs),
}

/// Arguments shared by every stage subcommand.
#[derive(Args, Debug, Clone)]
pub struct StageArgs {
    /// The stage's parameters (TOML table, the same keys as in a pipeline's `[stage.params]`).
    pub params: PathBuf,
    /// Output directory.
    #[arg(long, short, default_value = "out")]
    pub out: PathBuf,
    /// Override a parameter: `--set key=value` (value parsed as TOML), repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

#[derive(Args, Debug, Clone)]
pub struct SimulateArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Output directory (default: the scene's `output.dir`, else `out/<scene name>`).
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// Continue from the newest checkpoint in the output directory.
    #[arg(long)]
    pub resume: bool,
}

pub fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run { pipeline, force } => crate::pipeline::run_file(&pipeline, force),
        Command::Radiograph(a) => crate::stages::run_standalone("radiograph", &a),
        Command::Synth(SynthCommand::Radiograph(a)) => crate::stages::run_standalone("synth-radiograph", &a),
        Command::Digitise(a) => crate::stages::run_standalone("digitise", &a),
        Command::Report(a) => crate::stages::run_standalone("report", &a),
        Command::Simulate(a) => crate::scenes::simulate(&a.scene, a.out.as_deref(), a.resume),
        Command::Bench(a) => crate::bench::run(&a),
    }
}
