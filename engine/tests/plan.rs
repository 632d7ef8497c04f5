//! Experiment design against independent oracles: the predicted standard error of a Coulomb
//! coefficient on a free decay against the information of the exact piecewise solution
//! (differentiated by central differences) and against the spread of fits of noisy records;
//! the Monte Carlo acceptance cases (a Stribeck pair on the FMM stage, LuGre's bristle
//! stiffness at two sample rates, multisine bands on a driven axis) are `#[ignore]`d and run
//! with `cargo test -p frictionid-engine --test integration plan -- --ignored`.

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, ParamOptions};
use frictionid_engine::plan::{
    plan, Assumed, Criterion, Experiment, ExperimentInput, Multisine, Noise, Plan, PlanRequest,
};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record, SimOptions};
use frictionid_models::{Coulomb, FrictionModel};

/// A plan request over `candidates` for `model` on `osc` with every free parameter.
fn request<'a>(
    osc: Oscillator,
    model: &'a (dyn FrictionModel + 'static),
    free: &[&str],
    candidates: Vec<Experiment>,
    noise: f64,
) -> PlanRequest<'a> {
    PlanRequest {
        assumed: Assumed {
            oscillator: osc,
            model,
            params: ParamOptions {
                free: Some(free.iter().map(|s| s.to_string()).collect()),
                ..ParamOptions::default()
            },
            sim: FitOptions::default().sim,
        },
        candidates,
        taken: Vec::new(),
        targets: None,
        choose: 1,
        criterion: Criterion::D,
        noise: Noise {
            velocity: Some(noise),
            correlation: 0.0,
        },
        reach: 0.5,
        suggest: false,
    }
}

/// The information about mu of the exact Coulomb motion from `x0` at `times`, with
/// AR(1) noise of deviation `sigma` and lag-one correlation `rho`: sum of the whitened
/// derivative dv/dmu squared over sigma^2, dv/dmu by central differences of the closed form.
fn exact_information(
    osc: &Oscillator,
    mu: f64,
    x0: f64,
    times: &[f64],
    sigma: f64,
    rho: f64,
) -> f64 {
    let v = |m: f64| {
        coulomb_free_vibration(osc, m * osc.normal_force, x0, times)
            .unwrap()
            .v
    };
    let h = 1e-6;
    let (up, down) = (v(mu + h), v(mu - h));
    let d: Vec<f64> = up
        .iter()
        .zip(&down)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect();
    let gain = 1.0 / (1.0 - rho * rho).sqrt();
    let whitened = (0..d.len()).map(|i| {
        if i == 0 {
            d[0]
        } else {
            (d[i] - rho * d[i - 1]) * gain
        }
    });
    whitened.map(|w| w * w).sum::<f64>() / (sigma * sigma)
}

/// The paper's stage, mu 0.2, released from 14 mm, 1.5 s at 1 kHz, noise 2e-4 m/s: the
/// predicted standard error of mu is 1/sqrt(I) of the exact solution's information, white
/// and coloured (rho 0.6); a plan that ignored the correlation would be caught (the
/// coloured prediction differs from the white one by far more than the tolerance).
#[test]
fn coulomb_predicted_std_matches_the_exact_solution() {
    let osc = Oscillator::fmm();
    let law = Coulomb { mu: 0.2 };
    let candidate = Experiment::release(0.014, 1.5, 1000.0);
    let times = uniform_times(1.5, 1000.0);
    let mut predicted = Vec::new();
    for rho in [0.0, 0.6] {
        let mut req = request(osc, &law, &["mu"], vec![candidate.clone()], 2e-4);
        req.noise.correlation = rho;
        let p = plan(&req).unwrap();
        let std = p.candidates[0].predicted_std[0].unwrap();
        let exact = 1.0 / exact_information(&osc, 0.2, 0.014, &times, 2e-4, rho).sqrt();
        assert!(
            (std / exact - 1.0).abs() < 0.01,
            "rho {rho}: {std} vs {exact}"
        );
        assert_eq!(p.predicted_std, p.candidates[0].predicted_std);
        assert!(p.out_of_reach.is_empty());
        predicted.push(std);
    }
    assert!(predicted[1] / predicted[0] > 1.3, "{predicted:?}");
}

/// Thirty noisy records of the same experiment fitted for mu: the spread of the estimates
/// agrees with the predicted standard error (the spread of 30 samples is itself known to
/// about 13 %, so within 40 %), and the longer, quieter of two candidates is chosen.
#[test]
fn coulomb_prediction_matches_the_spread_of_fits() {
    let osc = Oscillator::fmm();
    let law = Coulomb { mu: 0.2 };
    let quiet = Experiment {
        velocity_noise: Some(1e-4),
        ..Experiment::release(0.014, 1.5, 1000.0)
    };
    let candidates = vec![Experiment::release(0.014, 1.5, 1000.0), quiet];
    let p = plan(&request(osc, &law, &["mu"], candidates, 2e-4)).unwrap();
    assert_eq!(p.recommended, vec![1]);
    let predicted = p.candidates[0].predicted_std[0].unwrap();
    let times = uniform_times(1.5, 1000.0);
    let clean = coulomb_free_vibration(&osc, 0.2 * osc.normal_force, 0.014, &times)
        .unwrap()
        .v;
    let estimates: Vec<f64> = (0..30)
        .map(|seed| {
            let mut v = clean.clone();
            add_gaussian_noise(&mut v, 2e-4, 500 + seed);
            let rec = Record::new("noisy", times.clone(), v, 0.014);
            let opts = FitOptions {
                params: ParamOptions {
                    guess: false,
                    ..ParamOptions::default()
                },
                ..FitOptions::default()
            };
            fit(&osc, &law, &[rec], &opts).unwrap().value("mu").unwrap()
        })
        .collect();
    let spread = std_dev(&estimates);
    assert!(
        (spread / predicted - 1.0).abs() < 0.4,
        "spread {spread} vs predicted {predicted}"
    );
}

fn std_dev(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Fits `law`'s free parameters `free` (starting at the truth) to each of `sets` records
/// and returns each parameter's estimates, in `free`'s order.
fn spreads(
    osc: &Oscillator,
    law: &(dyn FrictionModel + 'static),
    free: &[&str],
    sets: impl Iterator<Item = Vec<Record>>,
) -> Vec<f64> {
    let opts = FitOptions {
        params: ParamOptions {
            free: Some(free.iter().map(|s| s.to_string()).collect()),
            guess: false,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let mut estimates = vec![Vec::new(); free.len()];
    for records in sets {
        let r = fit(osc, law, &records, &opts).unwrap();
        for (e, name) in estimates.iter_mut().zip(free) {
            e.push(r.value(name).unwrap());
        }
    }
    estimates.iter().map(|e| std_dev(e)).collect()
}

/// Noisy free-decay records of `experiments` under `law` simulated with `sim` (seed `seed`,
/// one per record).
fn noisy_records(
    sim: &SimOptions,
    osc: &Oscillator,
    law: &dyn FrictionModel,
    experiments: &[&Experiment],
    noise: f64,
    seed: u64,
) -> Vec<Record> {
    experiments
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let mut rec = e.record(osc, law, sim, noise).unwrap();
            let mut v = rec.velocity().to_vec();
            add_gaussian_noise(&mut v, noise, seed * 7 + i as u64);
            rec.velocity_mut().copy_from_slice(&v);
            rec
        })
        .collect()
}

fn stribeck_fmm() -> frictionid_models::Stribeck {
    frictionid_models::Stribeck {
        mu_c: 0.20,
        mu_s: 0.30,
        v_s: 0.01,
        delta: 2.0,
        viscous: 0.0,
    }
}

fn index_of(p: &Plan, name: &str) -> usize {
    p.parameters.iter().position(|q| q.name == name).unwrap()
}

/// The FMM stage with the Stribeck truth, releases 4-30 mm, 2 s at 1 kHz, noise 2e-4 m/s,
/// two records for v_s and mu_s: the recommended pair's predicted standard errors agree with
/// the spread of 100 noisy fits within 20 %, and its v_s standard error is at most half the
/// paper's pair's (10 and 22 mm), predicted and in the Monte Carlo.
#[test]
#[ignore = "Monte Carlo: 200 Stribeck fits"]
fn stribeck_pair_prediction_matches_monte_carlo() {
    let osc = Oscillator::fmm();
    let law = stribeck_fmm();
    let free = ["mu_c", "mu_s", "v_s"];
    let releases = [4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 18.0, 22.0, 26.0, 30.0];
    let candidates: Vec<Experiment> = releases
        .iter()
        .map(|mm| Experiment::release(mm * 1e-3, 2.0, 1000.0))
        .collect();
    let mut req = request(osc, &law, &free, candidates.clone(), 2e-4);
    req.choose = 2;
    req.targets = Some(vec!["v_s".into(), "mu_s".into()]);
    let p = plan(&req).unwrap();
    let paper: Vec<&Experiment> = vec![&candidates[3], &candidates[7]];
    let mut paper_req = request(
        osc,
        &law,
        &free,
        paper.iter().map(|e| (*e).clone()).collect(),
        2e-4,
    );
    paper_req.choose = 2;
    let paper_plan = plan(&paper_req).unwrap();
    let chosen: Vec<&Experiment> = p.recommended.iter().map(|&i| &candidates[i]).collect();
    let vs = index_of(&p, "v_s");
    let mc = |set: &[&Experiment], seed: u64| {
        spreads(
            &osc,
            &law,
            &free,
            (0..100)
                .map(|k| noisy_records(&SimOptions::default(), &osc, &law, set, 2e-4, seed + k)),
        )
    };
    let rec_mc = mc(&chosen, 1000);
    let paper_mc = mc(&paper, 5000);
    eprintln!(
        "recommended {:?}: predicted {:?}, Monte Carlo {:?}; paper pair: predicted {:?}, Monte Carlo {:?}",
        chosen.iter().map(|e| e.x0).collect::<Vec<_>>(),
        p.predicted_std, rec_mc, paper_plan.predicted_std, paper_mc
    );
    for (i, name) in free.iter().enumerate() {
        let predicted = p.predicted_std[index_of(&p, name)].unwrap();
        if *name != "mu_c" {
            assert!(
                (rec_mc[i] / predicted - 1.0).abs() < 0.2,
                "{name}: {} vs {predicted}",
                rec_mc[i]
            );
        }
    }
    let (rec_vs, paper_vs) = (
        p.predicted_std[vs].unwrap(),
        paper_plan.predicted_std[vs].unwrap(),
    );
    assert!(
        rec_vs <= 0.5 * paper_vs,
        "predicted v_s {rec_vs} vs paper {paper_vs}"
    );
    assert!(
        rec_mc[2] <= 0.5 * paper_mc[2],
        "Monte Carlo v_s {} vs paper {}",
        rec_mc[2],
        paper_mc[2]
    );
}

/// What the plan and a fit of noisy records say about LuGre's sigma0 at one sample rate.
struct Sigma0Reach {
    /// The plan's out-of-reach finding for sigma0, if any.
    out: Option<frictionid_engine::plan::OutOfReach>,
    /// The plan's predicted relative standard error of sigma0.
    relative: Option<f64>,
    /// The fit's identifiability finding for sigma0 and its value.
    fitted: Option<frictionid_engine::identify::Identifiability>,
    value: f64,
}

impl Sigma0Reach {
    fn determined(&self) -> bool {
        self.fitted == Some(frictionid_engine::identify::Identifiability::Determined)
    }
}

/// `law` on the FMM stage released from the paper's three releases, 0.6 s at `rate`, noise
/// 2e-4 m/s: the plan for the five free parameters (sigma2 held, with the smallest changes
/// looked for) and a fit of noisy records of the same experiments (simulated with `sim`,
/// seed `seed`) from LuGre's defaults, sigma2 held at the value the plan assumes (LuGre's
/// default 0.5 against the truth's 2 is another law: its fit ends 1.4 times the noise with
/// sigma0 bounded only from below).
fn sigma0_reach(
    law: &frictionid_models::LuGre,
    rate: f64,
    sim: &SimOptions,
    seed: u64,
) -> Sigma0Reach {
    let osc = Oscillator::fmm();
    let free = ["sigma0", "sigma1", "mu_c", "mu_s", "v_s"];
    let candidates: Vec<Experiment> = [0.010, 0.014, 0.022]
        .iter()
        .map(|&x0| Experiment::release(x0, 0.6, rate))
        .collect();
    let mut req = request(osc, law, &free, candidates.clone(), 2e-4);
    req.choose = 3;
    req.suggest = true;
    let p = plan(&req).unwrap();
    let set: Vec<&Experiment> = candidates.iter().collect();
    let records = noisy_records(sim, &osc, law, &set, 2e-4, seed);
    let opts = FitOptions {
        params: ParamOptions {
            free: Some(free.iter().map(|s| s.to_string()).collect()),
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let start = frictionid_models::LuGre {
        sigma2: law.sigma2,
        ..frictionid_models::LuGre::default()
    };
    let r = fit(&osc, &start, &records, &opts).unwrap();
    let sigma0 = r.param("sigma0").unwrap();
    let out = Sigma0Reach {
        out: p
            .out_of_reach
            .iter()
            .find(|o| o.parameter == "sigma0")
            .cloned(),
        relative: p.relative(&p.predicted_std, index_of(&p, "sigma0")),
        fitted: sigma0.identifiability,
        value: sigma0.value,
    };
    eprintln!(
        "sigma0 {:e} at {rate} Hz: plan relative std {:?}, out of reach: {:?}; fit {:?} {:e}",
        law.sigma0,
        out.relative,
        out.out.as_ref().map(|o| &o.message),
        out.fitted,
        out.value
    );
    out
}

/// LuGre's bristle stiffness at 1 kHz and 20 kHz: the plan puts sigma0 out of reach
/// exactly when the identifiability finding of a fit of noisy records does not call it
/// determined, both ways.
///
/// Bristles of 1e7 N/m (`stiff_lugre_truth`) are within reach at both rates (plan: 23 % and
/// 5.2 %) and both fits determine them. Bristles of 1e10 N/m (`unresolved_lugre_truth`, ringing
/// at 4.9 kHz) are out of reach at 1 kHz: the records would not tell them from a rigid
/// contact (the Stribeck limit fits them within chi2 0.88, where the fit's test at 3.84
/// would reject it 9 times in 10 only from 10.5) and the fit bounds sigma0 only from below;
/// at 20 kHz (chi2 about 17) the plan puts them within reach and the fit determines them.
/// The 1 kHz message names, among its changes, a sample rate that reaches sigma0 (20 kHz),
/// no faster than the 20 kHz the second case confirms. Of eight noise seeds the fits agree
/// at 1 kHz in seven (a lower bound) and at 20 kHz in eight (determined).
#[test]
#[ignore = "slow: LuGre fits at 20 kHz (about 15 s)"]
fn lugre_sigma0_reach_agrees_with_the_fits_findings() {
    use frictionid_engine::plan::Dimension;
    use frictionid_engine::simulate::Integrator;
    let stiff = crate::util::stiff_lugre_truth();
    for rate in [1000.0, 20_000.0] {
        let at = sigma0_reach(&stiff, rate, &SimOptions::default(), 77);
        assert!(at.out.is_none(), "{rate} Hz: {:?}", at.out);
        assert!(at.determined(), "{rate} Hz: {:?}", at.fitted);
    }
    let unresolved = crate::util::unresolved_lugre_truth();
    let rodas = SimOptions {
        integrator: Integrator::Rodas,
        ..SimOptions::default()
    };
    let slow = sigma0_reach(&unresolved, 1000.0, &rodas, 100);
    let fast = sigma0_reach(&unresolved, 20_000.0, &rodas, 100);
    let out = slow.out.as_ref().expect("sigma0 out of reach at 1 kHz");
    assert!(out.rigid_limit.is_some(), "{}", out.message);
    assert!(!slow.determined(), "1 kHz: {:?}", slow.fitted);
    assert!(fast.out.is_none(), "20 kHz: {:?}", fast.out);
    assert!(fast.determined(), "20 kHz: {:?}", fast.fitted);
    let named = out
        .changes()
        .find(|c| c.dimension == Dimension::SampleRate)
        .expect("a sample rate named");
    assert!(
        named.to.iter().all(|&r| r > 1000.0 && r <= 20_000.0),
        "{named:?}"
    );
    assert!(out.message.contains("sample rate 1000"), "{}", out.message);
}

/// A driven slide (2 kg, no spring, N 20 N) with the Stribeck truth under multisines of
/// three bands: the band the plan recommends gives the smallest Monte Carlo spread of v_s.
#[test]
#[ignore = "Monte Carlo: 450 driven Stribeck fits"]
fn driven_band_recommended_has_the_smallest_vs_spread() {
    use frictionid_engine::axis::{NoRestoring, Restoring};
    let osc = Oscillator {
        mass: 2.0,
        damping: 0.0,
        stiffness: 1.0,
        normal_force: 20.0,
        restoring: Restoring::None(NoRestoring),
        ..Oscillator::fmm()
    };
    let law = stribeck_fmm();
    let free = ["mu_c", "mu_s", "v_s"];
    let bands = [[0.2, 1.0], [1.0, 5.0], [5.0, 25.0]];
    let candidates: Vec<Experiment> = bands
        .iter()
        .map(|&band| Experiment {
            name: format!("{band:?} Hz"),
            x0: 0.0,
            input: Some(ExperimentInput::Multisine(Multisine {
                amplitude: 10.0,
                band,
                components: 8,
            })),
            ..Experiment::release(0.0, 2.0, 1000.0)
        })
        .collect();
    let mut req = request(osc, &law, &free, candidates.clone(), 2e-4);
    req.targets = Some(vec!["v_s".into()]);
    let p = plan(&req).unwrap();
    let vs = index_of(&p, "v_s");
    let mc: Vec<f64> = candidates
        .iter()
        .enumerate()
        .map(|(i, e)| {
            spreads(
                &osc,
                &law,
                &free,
                (0..150).map(|k| {
                    noisy_records(
                        &SimOptions::default(),
                        &osc,
                        &law,
                        &[e],
                        2e-4,
                        900 + 1000 * i as u64 + k,
                    )
                }),
            )[2]
        })
        .collect();
    eprintln!(
        "bands {bands:?}: predicted v_s std {:?}, Monte Carlo {mc:?}, recommended {:?}",
        p.candidates
            .iter()
            .map(|c| c.predicted_std[vs])
            .collect::<Vec<_>>(),
        p.recommended
    );
    let best = (0..3).min_by(|&a, &b| mc[a].total_cmp(&mc[b])).unwrap();
    assert_eq!(p.recommended, vec![best]);
}
