//! The engine's tests that register friction laws of their own (typetag's registry is the
//! whole binary's): built apart from tests.rs, whose "every registered model" tests would
//! otherwise run these laws too.

mod energy;
mod integrated_sensitivities;
mod simulate_custom;
mod starts;
mod util;
