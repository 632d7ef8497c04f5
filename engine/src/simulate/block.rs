//! Samples of a law without internal states, written in blocks: the stepper sweeps its dense
//! output over a run of sample times, the forces and accelerations follow in one loop, and
//! the recorder takes whole columns. On the exact propagator this is most of a run's cost
//! (the paper's 140 mm Coulomb case: 2 001 samples against 7 segments).

use super::stepper::Stepper;
use super::{Dynamics, SampleBlock};

/// Samples per block: the columns stay in L1 (5 x 2 KiB).
pub(crate) const BLOCK: usize = 256;

/// The columns of one block.
pub(crate) struct BlockBuffer {
    x: [f64; BLOCK],
    v: [f64; BLOCK],
    a: [f64; BLOCK],
    friction: [f64; BLOCK],
}

impl BlockBuffer {
    pub(super) fn new() -> Self {
        Self {
            x: [0.0; BLOCK],
            v: [0.0; BLOCK],
            a: [0.0; BLOCK],
            friction: [0.0; BLOCK],
        }
    }

    /// The moving state at `times` (at most [`BLOCK`]) from the stepper's last step; with
    /// `forces`, the friction force of slip direction `dir` and the acceleration as well (the
    /// law's affine form a + b v where it declares one, `slip_force` otherwise).
    pub(super) fn moving<S: Stepper>(
        &mut self,
        stepper: &S,
        times: &[f64],
        scratch: &mut [f64],
        motion: Option<(&Dynamics<'_>, f64)>,
    ) {
        let n = times.len().min(BLOCK);
        stepper.interpolate_motion(times, &mut self.x[..n], &mut self.v[..n], scratch);
        let Some((dynamics, dir)) = motion else {
            return;
        };
        let affine = dynamics
            .switching
            .filter(|_| dynamics.conditions.is_none())
            .and_then(|law| law.affine_slip(dir, dynamics.normal));
        let rows = times.iter().zip(&self.x[..n]).zip(&self.v[..n]);
        let out = self.a[..n].iter_mut().zip(&mut self.friction[..n]);
        for (((&t, &x), &v), (a, f)) in rows.zip(out) {
            *f = match affine {
                Some((offset, slope)) => offset + slope * v,
                None => dynamics.force(t, x, v, &[], dir),
            };
            *a = dynamics.accel(t, x, v, *f);
        }
    }

    /// `n` samples at rest at `x`, the friction of row i `friction(i)` (what holds the mass
    /// against the restoring force and the input), no acceleration.
    pub(super) fn at_rest(&mut self, n: usize, x: f64, friction: impl Fn(usize) -> f64) {
        let n = n.min(BLOCK);
        self.x[..n].fill(x);
        self.v[..n].fill(0.0);
        self.a[..n].fill(0.0);
        for (i, f) in self.friction[..n].iter_mut().enumerate() {
            *f = friction(i);
        }
    }

    /// The first `times.len()` rows with their times.
    pub(super) fn view<'a>(&'a self, times: &'a [f64]) -> SampleBlock<'a> {
        let n = times.len().min(BLOCK);
        SampleBlock {
            t: &times[..n],
            x: &self.x[..n],
            v: &self.v[..n],
            a: &self.a[..n],
            friction: &self.friction[..n],
        }
    }
}
