//! The built-in friction models, one per file.

mod coulomb;
mod coulomb_asymmetric;
mod coulomb_load;
mod dahl;
mod expression;
mod gms;
mod gms_quadrature;
mod gms_relaxation;
mod gms_sharpness;
mod gms_steps;
mod gms_table;
mod lugre;
mod makkar;
mod none;
mod position_ripple;
mod stribeck;
mod viscous_coulomb;
mod viscous_coulomb_asymmetric;

pub use coulomb::Coulomb;
pub use coulomb_asymmetric::CoulombAsymmetric;
pub use coulomb_load::{CoulombLoad, LOAD_CHANNEL};
pub use dahl::Dahl;
pub use expression::{Expression, ExpressionConfig};
pub use gms::{Gms, GmsConfig, GmsElement, PerElement, MAX_ELEMENTS};
pub use lugre::LuGre;
pub use makkar::Makkar;
pub use none::NoFriction;
pub use position_ripple::PositionRipple;
pub use stribeck::{mu_s_warning, Stribeck};
pub use viscous_coulomb::ViscousCoulomb;
pub use viscous_coulomb_asymmetric::ViscousCoulombAsymmetric;
