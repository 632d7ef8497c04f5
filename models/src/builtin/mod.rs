//! The built-in friction models, one per file.

mod coulomb;
mod dahl;
mod lugre;
mod none;
mod stribeck;
mod viscous_coulomb;

pub use coulomb::Coulomb;
pub use dahl::Dahl;
pub use lugre::LuGre;
pub use none::NoFriction;
pub use stribeck::Stribeck;
pub use viscous_coulomb::ViscousCoulomb;
