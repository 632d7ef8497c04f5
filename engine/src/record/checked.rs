//! The memory of a record's sample checks: once its channels' lengths, their finiteness and
//! the order of its time stamps passed [`super::Record::validate_channels`], they pass until
//! the samples change (every change goes through the record's methods, which forget it); only
//! the count of samples, which each caller asks for its own minimum, is checked again. A fit
//! and the energy analysis it runs each validate every record; the scan of the samples was
//! 5 % of a first Coulomb fit.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether the samples passed their checks.
#[derive(Debug, Default)]
pub(crate) struct SampleCheck(AtomicBool);

impl SampleCheck {
    /// Whether the samples passed their checks since they last changed.
    pub(crate) fn passed(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Notes that the samples passed.
    pub(crate) fn pass(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Forgets the checks (the samples changed).
    pub(crate) fn clear(&mut self) {
        *self.0.get_mut() = false;
    }
}

impl Clone for SampleCheck {
    /// A clone has the same samples, so the same checks stand.
    fn clone(&self) -> Self {
        Self(AtomicBool::new(self.passed()))
    }
}
