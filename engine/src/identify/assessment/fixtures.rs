//! Fixtures of the assessment's unit tests: coloured noise and a record fit made of given
//! series.

use crate::identify::values::result::{FitSeries, RecordFit, SampleAxes};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// AR(1) noise of stationary standard deviation `sd` and lag-1 correlation `phi`.
pub(crate) fn ar1_noise(n: usize, sd: f64, phi: f64, seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let innovation = Normal::new(0.0, sd * (1.0 - phi * phi).sqrt()).unwrap();
    let mut e = Normal::new(0.0, sd).unwrap().sample(&mut rng);
    (0..n)
        .map(|_| {
            let out = e;
            e = phi * e + innovation.sample(&mut rng);
            out
        })
        .collect()
}

/// A fit of record `r` released at `x0` that compared `channel`: `measured` against `fitted`
/// at the times `time` (none: not kept), nothing else judged.
pub(crate) fn record_fit_of(
    channel: &str,
    x0: f64,
    time: Vec<f64>,
    measured: Vec<f64>,
    fitted: Vec<f64>,
) -> RecordFit {
    RecordFit {
        file: "r".into(),
        x0,
        release_time: None,
        samples: measured.len(),
        sliding: None,
        unreliable_target: None,
        robust_weights: None,
        channel: channel.into(),
        rms_residual: 0.0,
        channels: Vec::new(),
        energy_force: None,
        axes: SampleAxes {
            time,
            ..SampleAxes::default()
        },
        series: FitSeries {
            measured,
            fitted,
            ..FitSeries::default()
        },
    }
}
