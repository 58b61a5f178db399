//! Scenes: a simulation set-up in SI units, read from a TOML file of sections
//! ([`schema`]); the sections it has name the physics it runs, and only that is built
//! ([`models`]: grains, liquid, or both). Every scene runs through the one time loop
//! ([`timeloop`]) with observers ([`observers`]) for the series, snapshots ([`snapshot`]:
//! tables that can be read back, and VTK), stop conditions and progress, and checkpoints that
//! resume to the same bits. Scenes return what they wrote ([`run::SceneResult`]); the
//! `simulate` stage draws the figures. Format: docs/scenes.md.

pub mod build;
pub mod models;
pub mod observers;
pub mod run;
pub mod schema;
pub mod snapshot;
pub mod sphere_table;
pub mod timeloop;

#[cfg(test)]
mod tests;
