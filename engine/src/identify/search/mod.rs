//! The search for the optimum, on the problem's floor: the free parameters the options ask
//! for ([`free_params`]), the bounded Levenberg-Marquardt solver ([`lm`], its
//! normal equations in `normal_equations`), the multi-start
//! runs ([`starts`]), where the starts come from ([`strategy`]: local, staged from simpler
//! laws, global; the presliding travel the records show, [`presliding`]), the further starts of a free decay that sticks ([`further`]) and the
//! force-domain prefit's options and finding ([`prefit`]).
//! Imports the values and the problem; knows nothing of statistics or findings of a fit.

pub(crate) mod free_params;
pub(crate) mod further;
pub mod lm;
mod normal_equations;
pub(crate) mod prefit;
mod presliding;
pub mod starts;
pub(crate) mod strategy;

pub use free_params::{build_layout, Layout};
pub use lm::LevenbergMarquardt;
pub use starts::{DEFAULT_STARTS, MAX_STARTS, SCREEN_ITERATIONS};
