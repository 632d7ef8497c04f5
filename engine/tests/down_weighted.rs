//! The samples a robust loss down-weights are kept and said: a driven slide (M 12 kg, viscous
//! 30 N s/m, Coulomb 8 N) under a multisine, simulated by the engine's event-locating driver,
//! its input carrying 0.2 N of Gaussian noise and, at known samples, spikes of 30 noise
//! levels. Fitted by inverse dynamics with `loss = "huber"`, the result keeps each compared
//! sample's weight, and the samples below a weight of one half are the spikes (and few
//! others); least squares keeps no weights.

use crate::util::{
    driven_from_rest, inverse_dynamics_options, multisine, sample_times, serial, Tone,
};
use frictionid_engine::identify::values::search::Loss;
use frictionid_engine::identify::{fit, Check, FitResult, RobustWeights, Status};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::testing::driven_slide;
use frictionid_engine::Record;
use frictionid_models::ViscousCoulomb;

const RATE: f64 = 2000.0;
const SECONDS: f64 = 2.0;
const NOISE: f64 = 0.2;
/// Every this many samples the input carries a spike, of alternating sign.
const SPIKE_EVERY: usize = 197;
const SPIKE: f64 = 30.0 * NOISE;

/// The drive's record, with spikes on its input when `spiked`, and the spikes' times.
fn drive(spiked: bool) -> (Record, Vec<f64>) {
    const TONES: [Tone; 3] = [(40.0, 0.7, 0.0), (20.0, 1.9, 1.1), (10.0, 3.3, 2.3)];
    let t = sample_times(SECONDS, RATE);
    let mut u: Vec<f64> = t.iter().map(|&t| multisine(&TONES, t)).collect();
    let law = ViscousCoulomb {
        mu: 8.0,
        viscous: 30.0,
    };
    let sim = driven_from_rest(&driven_slide(12.0, 0.0), &law, &t, &u);
    add_gaussian_noise(&mut u, NOISE, 21);
    let mut spikes = Vec::new();
    if spiked {
        for (n, i) in (SPIKE_EVERY..t.len()).step_by(SPIKE_EVERY).enumerate() {
            u[i] += if n % 2 == 0 { SPIKE } else { -SPIKE };
            spikes.push(t[i]);
        }
    }
    let record = Record::from_time_base("drive.csv", TimeBase::new(t).expect("a time base"))
        .with_channel(Channel::Displacement, sim.x)
        .with_channel(Channel::InputForce, u)
        .with_noise(Channel::InputForce, NOISE);
    (record, spikes)
}

/// Viscous + Coulomb fitted by inverse dynamics under `loss`.
fn fitted(record: Record, loss: Loss) -> FitResult {
    let (osc, mut opts) = inverse_dynamics_options();
    opts.search.loss = loss;
    let law = ViscousCoulomb {
        mu: 5.0,
        viscous: 10.0,
    };
    fit(&osc, &law, &[record], &serial(opts)).expect("a fit")
}

fn weights(r: &FitResult) -> &RobustWeights {
    r.records[0]
        .robust_weights
        .as_ref()
        .expect("robust weights")
}

/// Every spike the fit compares is down-weighted, and at most one sample in a hundred of the
/// others; the weights cover every compared sample, and a finding says how many and where.
#[test]
fn huber_marks_the_spikes_and_few_others() {
    let (record, spikes) = drive(true);
    let r = fitted(record, Loss::Huber);
    let w = weights(&r);
    let time = &r.records[0].axes.time;
    assert_eq!(w.weights.len(), time.len());
    let compared: Vec<f64> = spikes
        .iter()
        .copied()
        .filter(|s| time.contains(s))
        .collect();
    let marked = |s: &f64| w.times.contains(s);
    eprintln!(
        "{} of {} samples down-weighted, {} of {} compared spikes among them, least weight {:.3}",
        w.count,
        w.of,
        compared.iter().filter(|s| marked(s)).count(),
        compared.len(),
        w.least
    );
    assert!(compared.len() >= spikes.len() - 2, "{compared:?}");
    assert!(compared.iter().all(marked), "{:?}", w.times);
    let others = w.count - compared.len();
    assert!(others * 100 <= w.of, "{others} other samples");
    let finding = r
        .diagnostics
        .iter()
        .find(|f| f.check == Check::DownWeighted)
        .expect("a down-weighted finding");
    assert_eq!(finding.status, Status::Pass);
    assert!(
        finding
            .message
            .contains(&format!("{} of {}", w.count, w.of)),
        "{}",
        finding.message
    );
}

/// Without spikes few samples fall below one half; under least squares no weights are kept
/// and nothing is said.
#[test]
fn a_clean_record_has_few_marks_and_least_squares_none() {
    let (record, _) = drive(false);
    let r = fitted(record.clone(), Loss::Huber);
    let w = weights(&r);
    eprintln!("{} of {} samples down-weighted", w.count, w.of);
    assert!(w.count * 100 <= w.of, "{} of {}", w.count, w.of);
    let r = fitted(record, Loss::Linear);
    assert!(r.records[0].robust_weights.is_none());
    assert!(r.diagnostics.iter().all(|f| f.check != Check::DownWeighted));
}
