//! Where a run's samples go: the [`Recorder`] the driver writes into, the full recorder of
//! a [`Trajectory`] and the velocity-only recorder of a fit.

use super::mechanical::MechanicalEnergy;
use super::values::{Event, Rest, SimStats, Trajectory};
use crate::oscillator::Oscillator;
use frictionid_models::{FrictionModel, InternalStates};

/// Events, rest and statistics of a run.
pub(crate) struct RunOutput {
    pub events: Vec<Event>,
    pub rest: Option<Rest>,
    pub stats: SimStats,
}

/// Receives the samples.
pub(crate) trait Recorder {
    /// One sample: time, state, acceleration and friction force.
    fn sample(&mut self, t: f64, x: f64, v: f64, z: &[f64], a: f64, friction: f64);

    /// Whether the recorder reads accelerations and friction forces (when it does not, the
    /// driver may skip computing them: the values it passes are then meaningless).
    fn wants_forces(&self) -> bool {
        true
    }

    /// Whether the run should stop here (asked after every step; the samples written so far
    /// stay). Never, by default.
    fn halted(&mut self) -> bool {
        false
    }

    /// Consecutive samples of a law without internal states, as columns of equal length;
    /// the default records them one by one.
    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        let columns = block.t.iter().zip(block.x).zip(block.v);
        for (((&t, &x), &v), (&a, &f)) in columns.zip(block.a.iter().zip(block.friction)) {
            self.sample(t, x, v, &[], a, f);
        }
    }
}

/// A run of samples of a law without internal states, one column per output.
pub(crate) struct SampleBlock<'a> {
    pub t: &'a [f64],
    pub x: &'a [f64],
    pub v: &'a [f64],
    pub a: &'a [f64],
    pub friction: &'a [f64],
}

/// Records every output into the series of a [`Trajectory`] (events, rest and statistics are
/// the run's, added after it).
pub(super) struct FullRecorder<'a> {
    states: Option<&'a dyn InternalStates>,
    osc: Oscillator,
    normal: f64,
    pub(super) series: Trajectory,
}

impl<'a> FullRecorder<'a> {
    pub(super) fn new(
        osc: &Oscillator,
        model: &'a dyn FrictionModel,
        n: usize,
        n_states: usize,
    ) -> Self {
        let col = || Vec::with_capacity(n);
        Self {
            states: model.states(),
            osc: *osc,
            normal: osc.normal_force,
            series: Trajectory {
                time: col(),
                x: col(),
                v: col(),
                a: col(),
                states: (0..n_states).map(|_| col()).collect(),
                friction: col(),
                stored: col(),
                ..Trajectory::default()
            },
        }
    }
}

impl Recorder for FullRecorder<'_> {
    fn sample(&mut self, t: f64, x: f64, v: f64, z: &[f64], a: f64, friction: f64) {
        let out = &mut self.series;
        out.time.push(t);
        out.x.push(x);
        out.v.push(v);
        out.a.push(a);
        for (col, &zj) in out.states.iter_mut().zip(z) {
            col.push(zj);
        }
        out.friction.push(friction);
        // Static laws store nothing: the column is filled once at the end.
        if let (false, Some(states)) = (z.is_empty(), self.states) {
            out.stored.push(states.stored_energy(z, self.normal));
        }
    }

    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        let out = &mut self.series;
        out.time.extend_from_slice(block.t);
        out.x.extend_from_slice(block.x);
        out.v.extend_from_slice(block.v);
        out.a.extend_from_slice(block.a);
        out.friction.extend_from_slice(block.friction);
    }
}

impl FullRecorder<'_> {
    /// The energy columns from the recorded states, in one pass each after the run (the
    /// per-sample work stays with the samples themselves).
    pub(super) fn finish_energies(&mut self) {
        let out = &mut self.series;
        out.mechanical = MechanicalEnergy::of(&self.osc, &out.x, &out.v);
        if out.stored.len() < out.time.len() {
            out.stored.resize(out.time.len(), 0.0);
        }
    }
}

pub(super) struct VelocityRecorder<'a> {
    pub(super) v: &'a mut Vec<f64>,
    pub(super) watch: &'a mut dyn FnMut(usize) -> bool,
}

impl Recorder for VelocityRecorder<'_> {
    fn sample(&mut self, _t: f64, _x: f64, v: f64, _z: &[f64], _a: f64, _friction: f64) {
        self.v.push(v);
    }

    fn wants_forces(&self) -> bool {
        false
    }

    fn sample_block(&mut self, block: &SampleBlock<'_>) {
        self.v.extend_from_slice(block.v);
    }

    fn halted(&mut self) -> bool {
        (self.watch)(self.v.len())
    }
}
