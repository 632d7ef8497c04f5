//! The one rule for a record with nothing to identify friction from: no motion at all, or
//! motion within the velocity noise (a record of a stage at rest, a sensor's noise floor).

use crate::energy::record_motion;
use crate::error::EngineError;
use crate::record::noise::{difference_noise, RESPONSE_ORDER};
use crate::record::Record;

/// A record whose largest speed is within this many noise levels of zero has no motion
/// (Gaussian noise alone stays below 4.5 levels over a million samples).
pub(crate) const MOTION_OVER_NOISE: f64 = 5.0;

/// Whether `record` moves: its velocity (measured, or the differentiated displacement) must
/// exceed zero and [`MOTION_OVER_NOISE`] times its noise level (from third differences).
/// A record without a motion channel passes here (the residuals name what is missing).
pub fn check_moves(record: &Record) -> Result<(), EngineError> {
    let Some(motion) = record_motion(record) else {
        return Ok(());
    };
    let peak = motion.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let refuse = |reason: String| {
        Err(EngineError::Record {
            record: record.name.clone(),
            reason,
        })
    };
    if peak <= 0.0 {
        return refuse(
            "no motion: every velocity sample is 0, so there is no friction to identify".into(),
        );
    }
    let noise = difference_noise(&motion.v, RESPONSE_ORDER);
    if peak <= MOTION_OVER_NOISE * noise {
        return refuse(format!(
            "no motion above the noise: the largest speed {peak:e} is within {MOTION_OVER_NOISE} times the velocity noise {noise:e}, so there is no friction to identify"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::add_gaussian_noise;

    fn record(v: Vec<f64>) -> Record {
        let time = (0..v.len()).map(|i| i as f64 * 1e-3).collect();
        Record::new("r", time, v, 0.0)
    }

    #[test]
    fn rest_and_noise_alone_are_no_motion_and_a_small_swing_is() {
        assert!(check_moves(&record(vec![0.0; 500])).is_err());
        let mut noise = vec![0.0; 2000];
        add_gaussian_noise(&mut noise, 1e-4, 3);
        let e = check_moves(&record(noise.clone())).unwrap_err().to_string();
        assert!(e.contains("no motion above the noise"), "{e}");
        // A swing of ten noise levels moves.
        let swing: Vec<f64> = noise
            .iter()
            .enumerate()
            .map(|(i, n)| n + 1e-3 * (i as f64 * 0.01).sin())
            .collect();
        assert!(check_moves(&record(swing)).is_ok());
        // A constant-velocity run is motion without noise.
        assert!(check_moves(&record(vec![1e-3; 100])).is_ok());
    }
}
