//! Synthetic FMM records made by the engine with known truths and noise: the oracles of the
//! identifier's recovery tests.
#![allow(dead_code)]

use frictionid_engine::synthetic::release_records;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{FrictionModel, LuGre, Stribeck};

/// The releases of the paper: 10, 14 and 22 mm.
pub const RELEASES: [f64; 3] = [0.010, 0.014, 0.022];
/// The noise level of the acceptance set-up [m/s].
pub const NOISE: f64 = 2e-4;

/// Records of `model` on `osc` from the three releases, 2 s at 1 kHz, with Gaussian noise of
/// `noise` m/s (seeds `seed`, `seed + 1`, `seed + 2`).
pub fn records(osc: &Oscillator, model: &dyn FrictionModel, noise: f64, seed: u64) -> Vec<Record> {
    release_records(osc, model, &RELEASES, 2.0, 1000.0, noise, seed)
        .expect("simulation of the truth")
}

/// The LuGre truth of the dynamic-model recovery tests: sigma0 1e5 N/m, sigma1
/// 500 N s/m, sigma2 1 N s/m, mu_c 0.22, mu_s 0.30, v_s 0.01 m/s.
pub fn lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e5,
        sigma1: 500.0,
        sigma2: 1.0,
        mu_c: 0.22,
        mu_s: 0.30,
        v_s: 0.01,
    }
}

/// The stiff LuGre truth of the recovery tests: bristles of sigma0 1e7 N/m.
pub fn stiff_lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e7,
        sigma1: 4000.0,
        sigma2: 2.0,
        mu_c: 0.18,
        mu_s: 0.26,
        v_s: 0.005,
    }
}

/// A Stribeck law with a pronounced dip and viscous drag: mu_c 0.20, mu_s 0.28, v_s 0.02 m/s,
/// delta 2, viscous 3 N s/m.
pub fn stribeck_truth() -> Stribeck {
    Stribeck {
        mu_c: 0.20,
        mu_s: 0.28,
        v_s: 0.02,
        delta: 2.0,
        viscous: 3.0,
    }
}
