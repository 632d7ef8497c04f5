//! The built-in friction models, one per file.

mod coulomb;

pub use coulomb::Coulomb;
