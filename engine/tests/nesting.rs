//! Nesting on a driven axis: a slide of 12 kg with Dahl friction (bristle stiffness 5e4 N/m,
//! Coulomb level 8 N, linear hysteresis) and an input offset of 0.5 N under a multisine,
//! simulated here by classical Runge-Kutta on M v' = u - offset - F, F' = sigma0 v
//! (1 - F sgn(v) / F_c) with a step far below the bristles' time scale (not by the engine's
//! driver). Dahl holds Coulomb friction as its rigid limit, so its fit by inverse dynamics
//! must end at least as low as Coulomb's, stay ranked, and recover the truth. On the
//! viscous + Coulomb drive of the inverse-dynamics tests LuGre must end as low as
//! viscous_coulomb. The free-decay cases (records from the fixed-step Runge-Kutta reference
//! of `util::rk4_free_decay`, not from the engine's simulator) check that compare's velocity
//! route recommends the bristle law whose stiffness the records determine.

use crate::util::{inverse_dynamics_options, rel};
use frictionid_engine::identify::{compare, Check, Comparison, FitResult};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::Record;
use frictionid_models::{default_model, FrictionModel};
use std::f64::consts::PI;

const MASS: f64 = 12.0;
const SIGMA0: f64 = 5e4;
const COULOMB: f64 = 8.0;
const OFFSET: f64 = 0.5;
/// Sample rate [Hz], duration [s], input noise [N].
const RATE: f64 = 2000.0;
const DURATION: f64 = 3.0;
const NOISE: f64 = 0.2;

/// The multisine input u(t) \[N\]: five tones from 0.5 to 6 Hz.
fn input(t: f64) -> f64 {
    const TONES: [(f64, f64, f64); 5] = [
        (30.0, 0.5, 0.0),
        (15.0, 1.3, 1.1),
        (10.0, 2.2, 2.3),
        (6.0, 3.7, 0.4),
        (4.0, 6.0, 4.0),
    ];
    TONES
        .iter()
        .map(|(a, f, phase)| a * (2.0 * PI * f * t + phase).sin())
        .sum()
}

/// d(x, v, F)/dt of the slide with Dahl friction.
fn rate_of(t: f64, [_, v, f]: [f64; 3]) -> [f64; 3] {
    let r = 1.0 - f * v.signum() / COULOMB;
    [v, (input(t) - OFFSET - f) / MASS, SIGMA0 * v * r]
}

/// One classical Runge-Kutta step of length `h`.
fn rk4(t: f64, y: [f64; 3], h: f64) -> [f64; 3] {
    let add =
        |a: [f64; 3], b: [f64; 3], s: f64| [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]];
    let k1 = rate_of(t, y);
    let k2 = rate_of(t + 0.5 * h, add(y, k1, 0.5 * h));
    let k3 = rate_of(t + 0.5 * h, add(y, k2, 0.5 * h));
    let k4 = rate_of(t + h, add(y, k3, h));
    let mut out = y;
    for i in 0..3 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// The driven record from rest: position, velocity and the input with noise.
fn driven_record() -> Record {
    const SUBSTEPS: usize = 50;
    let n = (DURATION * RATE) as usize;
    let h = 1.0 / (RATE * SUBSTEPS as f64);
    let mut y = [0.0; 3];
    let (mut time, mut x, mut v, mut u) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        let t = k as f64 / RATE;
        time.push(t);
        x.push(y[0]);
        v.push(y[1]);
        u.push(input(t));
        for s in 0..SUBSTEPS {
            y = rk4(t + s as f64 * h, y, h);
        }
    }
    add_gaussian_noise(&mut u, NOISE, 5);
    Record::from_time_base("drive.csv", TimeBase::new(time).expect("a time base"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::InputForce, u)
        .with_noise(Channel::InputForce, NOISE)
}

/// Dahl, which holds Coulomb as its rigid limit, ends at least as low, stays ranked,
/// recovers its bristle stiffness and level and is the law compare recommends; Coulomb, the
/// wrong law, warns or fails `goodness_of_fit`.
#[test]
fn dahl_on_a_dahl_drive_ends_below_the_coulomb_it_holds() {
    let (osc, opts) = inverse_dynamics_options();
    let models: Vec<Box<dyn FrictionModel>> = ["coulomb", "dahl"]
        .iter()
        .map(|n| default_model(n).expect("a registered law"))
        .collect();
    let c = compare(&osc, &models, &[driven_record()], &opts).expect("a comparison");
    for f in &c.ranking {
        eprintln!(
            "{}: RMS {} N, {:?}",
            f.model,
            f.rms_residual,
            f.parameters
                .iter()
                .map(|p| (p.name.clone(), p.value))
                .collect::<Vec<_>>()
        );
    }
    eprintln!(
        "failed {:?}; verdict {:?}",
        c.failed,
        c.verdict.as_ref().map(|v| &v.message)
    );
    assert!(c.failed.is_empty(), "{:?}", c.failed);
    let rms = |name: &str| ranked(&c, name).rms_residual;
    assert!(rms("dahl") <= rms("coulomb"));
    let dahl = ranked(&c, "dahl");
    let (sigma0, mu_c) = (dahl.value("sigma0").unwrap(), dahl.value("mu_c").unwrap());
    assert!(rel(sigma0, SIGMA0) < 0.1, "sigma0 {sigma0}");
    assert!(rel(mu_c, COULOMB) < 0.02, "mu_c {mu_c}");
    let verdict = c.verdict.as_ref().expect("a verdict");
    assert_eq!(verdict.recommended.as_deref(), Some("dahl"));
    let coulomb = ranked(&c, "coulomb");
    crate::util::assert_flagged(coulomb, Check::GoodnessOfFit);
}

/// The viscous + Coulomb drive of the inverse-dynamics tests (its own event-locating
/// reference), position quantised to 1 um, input noise 0.2 N: LuGre holds viscous_coulomb (sigma2 the viscous
/// coefficient, its bristles infinitely stiff) and must end at least as low and stay ranked;
/// Dahl has no viscous term, so it does not hold viscous_coulomb and is ranked on its own
/// cost, never set aside as a failed search.
#[test]
fn lugre_on_a_viscous_coulomb_drive_ends_at_least_as_low() {
    let mut record = crate::inverse_dynamics::TRUTH.record(4000);
    if let Some(x) = record.channel_mut(Channel::Displacement) {
        x.iter_mut().for_each(|q| *q = (*q / 1e-6).round() * 1e-6);
    }
    if let Some(u) = record.channel_mut(Channel::InputForce) {
        add_gaussian_noise(u, NOISE, 9);
    }
    let record = record.with_noise(Channel::InputForce, NOISE);
    let c = drive_compare_with_every_law_ranked(record, &["viscous_coulomb", "dahl", "lugre"]);
    let rms = |name: &str| ranked(&c, name).rms_residual;
    assert!(rms("lugre") <= rms("viscous_coulomb") * (1.0 + 1e-3));
}

/// The same drive, whose configuration gives no normal force (the levels are forces): Dahl
/// does not hold the smoothed Coulomb law `expression` (mu N tanh(v / eps)), whose fitted
/// eps stands in for the viscous term, so Dahl is ranked on its own cost, not set aside as a
/// failed search. Compared under the oscillator's N = 0, every steady state vanished and any
/// law seemed to hold any other.
#[test]
fn without_a_normal_force_nesting_compares_the_levels_as_forces() {
    let record = crate::inverse_dynamics::TRUTH
        .record(4000)
        .with_noise(Channel::InputForce, NOISE);
    assert_eq!(
        inverse_dynamics_options().0.normal_force,
        0.0,
        "the test needs an oscillator without N"
    );
    let c = drive_compare_with_every_law_ranked(record, &["expression", "dahl"]);
    assert!(c.ranking.iter().any(|f| f.model == "dahl"));
}

/// The fit of `law` among the ranked laws of `c`.
fn ranked<'a>(c: &'a Comparison, law: &str) -> &'a FitResult {
    c.ranking.iter().find(|f| f.model == law).expect("ranked")
}

/// `laws` compared by inverse dynamics on the drive `record` (mass and offset fitted, no
/// normal force): no law fails, every one is ranked.
fn drive_compare_with_every_law_ranked(record: Record, laws: &[&str]) -> Comparison {
    let (osc, opts) = inverse_dynamics_options();
    let models: Vec<Box<dyn FrictionModel>> = laws
        .iter()
        .map(|n| default_model(n).expect("a registered law"))
        .collect();
    let c = compare(&osc, &models, &[record], &opts).expect("a comparison");
    for f in &c.ranking {
        eprintln!("{}: RMS {} N", f.model, f.rms_residual);
    }
    assert!(c.failed.is_empty(), "{:?}", c.failed);
    c
}

/// The FMM stage's free decays (the paper's three releases, 2 s at 1 kHz, 2e-4 m/s of noise)
/// of a LuGre truth whose bristle stiffness (1e5 N/m) the records determine: compare's
/// velocity route recommends lugre, which holds coulomb and stribeck, and the static laws
/// warn or fail `goodness_of_fit`.
#[test]
#[ignore = "slow: a compare of velocity fits with a dynamic law (about 2 s alone)"]
fn a_lugre_free_decay_recommends_lugre() {
    use crate::util::lugre_truth;
    free_decay_recommends(&lugre_truth(), &["coulomb", "stribeck", "lugre"]);
}

/// The same for a Dahl truth (bristle stiffness 1e5 N/m, mu_c 0.22): compare recommends
/// dahl, and coulomb, the law it holds, and stribeck warn or fail `goodness_of_fit`.
#[test]
#[ignore = "slow: a compare of velocity fits with a dynamic law (about 5 s alone)"]
fn a_dahl_free_decay_recommends_dahl() {
    let truth = frictionid_models::Dahl {
        sigma0: 1e5,
        mu_c: 0.22,
        alpha: 1.0,
    };
    free_decay_recommends(&truth, &["coulomb", "stribeck", "dahl"]);
}

/// Compares `laws` on the FMM free decays of `truth` made by the Runge-Kutta reference: the
/// truth's law (the last) is recommended and every other law warns or fails
/// `goodness_of_fit`.
fn free_decay_recommends(truth: &dyn FrictionModel, laws: &[&str]) {
    use crate::util::{rk4_records, NOISE};
    use frictionid_engine::identify::FitOptions;
    use frictionid_engine::Oscillator;
    let osc = Oscillator::fmm();
    let recs = rk4_records(&osc, truth, NOISE, 3);
    let models: Vec<Box<dyn FrictionModel>> = laws
        .iter()
        .map(|n| default_model(n).expect("a registered law"))
        .collect();
    let c = compare(&osc, &models, &recs, &FitOptions::default()).expect("a comparison");
    for f in &c.ranking {
        let goodness = f
            .diagnostics
            .iter()
            .find(|d| d.check == Check::GoodnessOfFit)
            .map(|d| (d.status, d.value));
        eprintln!(
            "{}: RMS {} m/s, goodness {goodness:?}, sigma0 {:?}",
            f.model,
            f.rms_residual,
            f.value("sigma0")
        );
    }
    let verdict = c.verdict.as_ref().expect("a verdict");
    eprintln!("failed {:?}; {}", c.failed, verdict.message);
    let law = truth.name();
    assert_eq!(verdict.recommended.as_deref(), Some(law));
    for f in c.ranking.iter().filter(|f| f.model != law) {
        crate::util::assert_flagged(f, Check::GoodnessOfFit);
    }
}

/// The Runge-Kutta reference is converged far below the noise: halving its step changes no
/// velocity sample of the LuGre and Dahl decays from the largest release by a hundredth of
/// the records' noise; and it is the same motion as the engine's simulator makes (within a
/// tenth of the noise), so both describe the truth the fits are judged against.
#[test]
fn the_reference_decays_are_converged_far_below_the_noise() {
    use crate::util::{rk4_free_decay, NOISE, RK4_SUBSTEPS};
    use frictionid_engine::synthetic::release_records;
    use frictionid_engine::Oscillator;
    let osc = Oscillator::fmm();
    let dahl = frictionid_models::Dahl {
        sigma0: 1e5,
        mu_c: 0.22,
        alpha: 1.0,
    };
    let lugre = crate::util::lugre_truth();
    for truth in [&lugre as &dyn FrictionModel, &dahl] {
        let x0 = 0.022;
        let (_, v) = rk4_free_decay(&osc, truth, x0, (2.0, 1000.0, RK4_SUBSTEPS));
        let (_, fine) = rk4_free_decay(&osc, truth, x0, (2.0, 1000.0, 2 * RK4_SUBSTEPS));
        let engine = release_records(&osc, truth, &[x0], 2.0, 1000.0, 0.0, 0).expect("a decay");
        let engine = engine[0].velocity();
        let worst = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        };
        let (step, simulators) = (worst(&v, &fine), worst(&v, engine));
        eprintln!(
            "{}: step error {step:.2e}, against the engine {simulators:.2e} m/s",
            truth.name()
        );
        assert!(step < 0.01 * NOISE, "{step}");
        assert!(simulators < 0.1 * NOISE, "{simulators}");
    }
    // A wrong truth is told apart: the Dahl decay with a 5 % lower level.
    let wrong = frictionid_models::Dahl {
        mu_c: 0.209,
        ..dahl
    };
    let (_, v) = rk4_free_decay(&osc, &dahl, 0.022, (2.0, 1000.0, RK4_SUBSTEPS));
    let (_, off) = rk4_free_decay(&osc, &wrong, 0.022, (2.0, 1000.0, RK4_SUBSTEPS));
    let gap = v
        .iter()
        .zip(&off)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(gap > 10.0 * NOISE, "{gap}");
}
