//! The built-in friction models, one per file.

mod coulomb;
mod dahl;
mod expression;
mod gms;
mod gms_steps;
mod lugre;
mod makkar;
mod none;
mod stribeck;
mod viscous_coulomb;

pub use coulomb::Coulomb;
pub use dahl::Dahl;
pub use expression::{Expression, ExpressionConfig};
pub use gms::{Gms, GmsConfig, GmsElement, PerElement, MAX_ELEMENTS};
pub use lugre::LuGre;
pub use makkar::Makkar;
pub use none::NoFriction;
pub use stribeck::{mu_s_warning, Stribeck};
pub use viscous_coulomb::ViscousCoulomb;
