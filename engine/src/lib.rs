//! The frictionid engine: the oscillator of the paper's Eq. (1), the event-detecting ODE
//! engine, the energy analysis (Eqs. 2-7) and the least-squares identifier.
//!
//! Library code: values in, values out; no printing.

pub mod data;
pub mod error;
pub mod exact;
pub mod identify;
pub mod oscillator;
pub mod record;
pub mod synthetic;

pub use error::EngineError;
pub use oscillator::Oscillator;
pub use record::Record;
