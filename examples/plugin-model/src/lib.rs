//! A friction model defined outside frictionid: the plugin example.
//!
//! This crate depends only on the public crates `frictionid-models` (the trait) and
//! `frictionid-cli` (the command line as a library). It defines one model,
//! [`StribeckPower`] (registry name `stribeck_power`), registers it with
//! `#[typetag::serde(name = "...")]`, and builds the binary `frictionid-plugin`, which is the
//! full `frictionid` command line with this model added: it lists, simulates, fits and
//! compares `stribeck_power` by name from a config. Nothing in `models/`, `engine/` or
//! `cli/` knows about it.
//!
//! typetag collects the registrations of every crate linked into the final binary; the
//! binary's `main` names this crate so that it is linked (see `src/main.rs`).

mod stribeck_power;

pub use stribeck_power::{StribeckPower, NAME};
