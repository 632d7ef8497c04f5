//! The makkar, gms and expression models: hand-computed forces, the Maxwell-element behaviour
//! of gms against its closed-form virgin curves, the exact equivalence of `mu * N * sign(v)`
//! with coulomb, formula errors with positions, configs and serde round trips.

use frictionid_models::*;

const N: f64 = 14.5;

// Table values (independent of the code under test).
const TANH_0_1: f64 = 0.099_667_994_624_955_82;
const TANH_0_5: f64 = 0.462_117_157_260_009_74;
const TANH_1: f64 = 0.761_594_155_955_764_9;
const TANH_2: f64 = 0.964_027_580_075_816_9;
const TANH_5: f64 = 0.999_909_204_262_595_1;
const TANH_10: f64 = 0.999_999_995_877_692_7;
const EXP_M1: f64 = 0.367_879_441_171_442_33;

/// The breakaway force of a set-valued law, `None` for any other.
fn static_limit(m: &dyn FrictionModel, normal: f64) -> Option<f64> {
    m.switching().and_then(|s| s.static_limit(normal))
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// The one-line message of the error `toml_model(text)` must give.
fn toml_error(text: &str) -> String {
    toml_model(text).unwrap_err().to_string()
}

fn toml_model(text: &str) -> Result<Built, ModelError> {
    let t: toml::Value = toml::from_str(text).map_err(|e| ModelError::Invalid(e.to_string()))?;
    build_toml(&t)
}

const VELOCITIES: [f64; 14] = [
    0.0, 1e-300, 1e-18, 1e-12, 1e-9, 1e-6, 1e-4, 0.001, 0.003, 0.01, 0.05, 0.2, 1.0, 7.5,
];

// ---------------------------------------------------------------- makkar

#[test]
fn makkar_reproduces_hand_computed_forces() {
    let m = Makkar {
        g1: 1.5,
        g2: 100.0,
        g3: 10.0,
        g4: 3.0,
        g5: 500.0,
        g6: 0.4,
    };
    // v = 0.01: g2 v = 1, g3 v = 0.1, g5 v = 5
    let f = 1.5 * (TANH_1 - TANH_0_1) + 3.0 * TANH_5 + 0.004;
    assert!(
        close(m.force(0.01, &[], N), f, 1e-15),
        "{}",
        m.force(0.01, &[], N)
    );
    // v = 0.1: g2 v = 10, g3 v = 1, g5 v = 50 (tanh(50) = 1 in double precision)
    let f = 1.5 * (TANH_10 - TANH_1) + 3.0 + 0.04;
    assert!(close(m.force(0.1, &[], N), f, 1e-15));
    // v = 0.001: g2 v = 0.1, g3 v = 0.01 (tanh(0.01) = 0.01 - 1e-6/3 + ...), g5 v = 0.5
    let tanh_0_01 = 0.01 - 1e-6 / 3.0 + 2e-10 / 15.0;
    let f = 1.5 * (TANH_0_1 - tanh_0_01) + 3.0 * TANH_0_5 + 0.0004;
    assert!(close(m.force(0.001, &[], N), f, 1e-14));
    // v = 0 and tiny v: tanh(x) = x, so F = (g1 (g2 - g3) + g4 g5 + g6) v
    assert_eq!(m.force(0.0, &[], N), 0.0);
    let slope = 1.5 * 90.0 + 3.0 * 500.0 + 0.4;
    assert!(close(m.force(1e-9, &[], N), slope * 1e-9, 1e-12));
    assert!(close(m.force(-1e-12, &[], N), -slope * 1e-12, 1e-12));
    // Smooth law: no set-valued force at rest, steady state = force, no dependence on N.
    assert_eq!(static_limit(&m, N), None);
    assert_eq!(m.steady_state(0.01, N), m.force(0.01, &[], N));
    assert_eq!(m.force(0.01, &[], 2.0 * N), m.force(0.01, &[], N));
    assert!(m.states().is_none(), "no internal states");
}

#[test]
fn makkar_is_odd_and_its_defaults_fit_the_fmm_scale() {
    let m = Makkar::default();
    for v in VELOCITIES {
        assert_eq!(m.force(-v, &[], N), -m.force(v, &[], N), "v = {v}");
    }
    // Coulomb level g4 = 2.9 N (mu = 0.2 at N = 14.5 N) once the bump has decayed.
    assert!(close(m.force(1.0, &[], N) - m.g6, 2.9, 1e-6));
    // The Stribeck bump tanh(200 v) - tanh(20 v) peaks at 200 v = 1.8366 (v = 9.18 mm/s):
    // the friction-minus-Coulomb-minus-viscous curve is highest there.
    let bump = |v: f64| m.force(v, &[], N) - 2.9 * (1000.0 * v).tanh() - 0.5 * v;
    let peak = (1..2000)
        .map(|i| f64::from(i) * 1e-5)
        .max_by(|a, b| bump(*a).total_cmp(&bump(*b)))
        .unwrap();
    assert!((peak - 0.00918).abs() < 2e-5, "{peak}");
    assert!(close(bump(peak), 1.9 * 0.768_845, 1e-5));
}

#[test]
fn makkar_params_metadata_and_warning() {
    let mut m = Makkar::default();
    let info = m.param_info();
    let names: Vec<&str> = info.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["g1", "g2", "g3", "g4", "g5", "g6"]);
    let units: Vec<String> = m.param_info().into_iter().map(|p| p.unit).collect();
    assert_eq!(units, ["N", "s/m", "s/m", "N", "s/m", "N s/m"]);
    m.set_params(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    assert_eq!(m.params(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    // g3 > g2: a dip, admissible but reported.
    assert_eq!(m.validate().unwrap().len(), 1);
    let e = toml_model("type = \"makkar\"\ng5 = -1.0").unwrap_err();
    assert!(
        matches!(e, ModelError::OutOfBounds { ref param, .. } if param == "g5"),
        "{e}"
    );
}

// ---------------------------------------------------------------- gms

fn one_element(k: f64, sharpness: f64) -> Gms {
    Gms {
        elements: vec![GmsElement {
            stiffness: k,
            weight: 1.0,
            damping: 0.0,
        }],
        mu_c: 0.2,
        mu_s: 0.3,
        v_s: 0.01,
        delta: 2.0,
        sharpness,
        viscous: 0.0,
    }
}

/// Two GMS elements (one damped) of stiffness `stiffness` and a sixth of it.
fn two_elements(sharpness: f64, stiffness: f64) -> Gms {
    Gms {
        elements: vec![
            GmsElement {
                stiffness,
                weight: 0.7,
                damping: 3.0,
            },
            GmsElement {
                stiffness: stiffness / 6.0,
                weight: 0.3,
                damping: 0.0,
            },
        ],
        sharpness,
        ..Gms::default()
    }
}

// GMS's exact steps at sharpnesses without a closed form (the Newton solve of the element's
// relaxation) pass the models' harness: its reference integration gives their states,
/// overloaded elements (large deflections, and a Stribeck curve that falls with speed) and
/// unloaded ones (deflections against the motion) included, and central differences give
/// their sensitivities in every parameter, the sharpness too.
#[test]
fn gms_steps_are_exact_at_sharpness_1_3() {
    if let Err(e) = testing::check_exact_steps(&two_elements(1.3, 2e5)) {
        panic!("{e}");
    }
}

#[test]
fn gms_steps_are_exact_at_sharpness_2_7() {
    if let Err(e) = testing::check_exact_steps(&two_elements(2.7, 2e5)) {
        panic!("{e}");
    }
}

/// At sharpness 6 and 20 the saturation is too stiff for the reference integration at some
/// probes (it stops, its step below round-off): every probe it integrates agrees with the
/// exact step and its sensitivities, and it integrates most of them.
fn check_where_the_reference_integrates(sharpness: f64) {
    let model = two_elements(sharpness, 2e4);
    let (mut checked, mut probes) = (0, 0);
    for normal in [1.0, 14.5] {
        for z in [0.0, 1e-6, -3e-5, 1e-4, -1e-3] {
            for z0 in [[z, z], [z, -0.5 * z]] {
                for v in [1e-4, 3e-3, 0.05, 0.3].into_iter().flat_map(|v| [v, -v]) {
                    for dt in [1e-4, 1e-3, 1e-2] {
                        probes += 1;
                        match testing::check_step(&model, Interval { v, normal, dt }, &z0) {
                            Ok(()) => checked += 1,
                            Err(e) if e.to_string().contains("reference integration failed") => {}
                            Err(e) => panic!("sharpness {sharpness}: {e}"),
                        }
                    }
                }
            }
        }
    }
    assert!(
        4 * checked >= 3 * probes,
        "sharpness {sharpness}: {checked} of {probes} probes integrated"
    );
}

#[test]
fn gms_steps_are_exact_at_sharpness_6_where_the_reference_integrates() {
    check_where_the_reference_integrates(6.0);
}

#[test]
fn gms_steps_are_exact_at_sharpness_20_where_the_reference_integrates() {
    check_where_the_reference_integrates(20.0);
}

/// Integrates dz/dt at constant velocity `v` for a time `t` with classical RK4 (`steps`
/// steps) and returns z.
fn integrate(m: &Gms, z0: &[f64], v: f64, t: f64, steps: usize) -> Vec<f64> {
    let n = z0.len();
    let h = t / steps as f64;
    let f = |z: &[f64]| {
        let mut d = vec![0.0; n];
        m.state_derivative(v, z, N, &mut d);
        d
    };
    let mut z = z0.to_vec();
    for _ in 0..steps {
        let k1 = f(&z);
        let z2: Vec<f64> = z.iter().zip(&k1).map(|(a, b)| a + 0.5 * h * b).collect();
        let k2 = f(&z2);
        let z3: Vec<f64> = z.iter().zip(&k2).map(|(a, b)| a + 0.5 * h * b).collect();
        let k3 = f(&z3);
        let z4: Vec<f64> = z.iter().zip(&k3).map(|(a, b)| a + h * b).collect();
        let k4 = f(&z4);
        for i in 0..n {
            z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    z
}

#[test]
fn gms_one_element_is_a_maxwell_element() {
    let k = 2e5;
    let v = 0.01;
    // Stribeck level at v = v_s: N (mu_c + (mu_s - mu_c) / e)
    let s = 14.5 * (0.2 + 0.1 * EXP_M1);
    for sharpness in [1.0, 2.0] {
        let m = one_element(k, sharpness);
        assert!(close(m.s(v, N), s, 1e-15));
        // The force is the spring force of the element: F = k z.
        for z in [0.0, 1e-9, -3e-6, 2e-5] {
            assert_eq!(m.force(v, &[z], N), k * z);
        }
        // Loading from rest at constant v: z = x while sticking, the closed-form virgin
        // curves (m = 1: s (1 - e^{-kx/s}); m = 2: s tanh(kx/s)) and then sliding at s(v).
        let delta = s / k; // breakaway displacement
        for (x_over_delta, exact_m1, exact_m2) in [
            (0.5, 1.0 - (-0.5f64).exp(), TANH_0_5),
            (1.0, 1.0 - EXP_M1, TANH_1),
            (2.0, 1.0 - (-2.0f64).exp(), TANH_2),
            (10.0, 1.0 - (-10.0f64).exp(), TANH_10),
        ] {
            let x = x_over_delta * delta;
            let z = integrate(&m, &[0.0], v, x / v, 4000);
            let exact = s * if sharpness == 1.0 { exact_m1 } else { exact_m2 };
            assert!(
                close(m.force(v, &z, N), exact, 1e-9),
                "m = {sharpness}, x/delta = {x_over_delta}: {} vs {exact}",
                m.force(v, &z, N)
            );
        }
        // Presliding stiffness: for x << delta the force is k x.
        let x = 1e-4 * delta;
        let z = integrate(&m, &[0.0], v, x / v, 100);
        assert!(close(m.force(v, &z, N), k * x, 2e-4));
        // Steady sliding: z = s / k is a fixed point and F = the Stribeck level.
        let mut d = [1.0];
        m.state_derivative(v, &[s / k], N, &mut d);
        assert!(d[0].abs() < 1e-17, "{}", d[0]);
        assert!(close(m.steady_state(v, N), s, 1e-15));
        assert!(close(m.steady_state(-v, N), -s, 1e-15));
        // After a reversal the element unloads elastically: dz/dt = v exactly.
        m.state_derivative(-v, &[s / k], N, &mut d);
        assert_eq!(d[0], -v);
        m.state_derivative(-v, &[0.3 * s / k], N, &mut d);
        assert_eq!(d[0], -v);
        // At rest nothing moves.
        m.state_derivative(0.0, &[0.7 * s / k], N, &mut d);
        assert_eq!(d[0], 0.0);
    }
}

#[test]
fn gms_sharp_elements_are_elastic_then_slip() {
    // m = 20: elastic almost up to the breakaway force, then sliding at the Stribeck level.
    let k = 1e5;
    let m = one_element(k, 20.0);
    let v = 0.002;
    let s = m.s(v, N);
    let delta = s / k;
    let z = integrate(&m, &[0.0], v, 0.5 * delta / v, 2000);
    // rho^20 = 1e-6 at rho = 0.5: the force is k x to about 1e-7.
    assert!(close(m.force(v, &z, N), 0.5 * s, 1e-6));
    let z = integrate(&m, &[0.0], v, 3.0 * delta / v, 20000);
    assert!(close(m.force(v, &z, N), s, 1e-6));
    // Over-saturated (the Stribeck level dropped): pulled back to the sliding force.
    let z = integrate(&m, &[1.5 * delta], v, 2.0 * delta / v, 20000);
    assert!(close(m.force(v, &z, N), s, 1e-6));
}

#[test]
fn gms_multi_element_force_is_the_sum_of_its_elements() {
    let elements = [(4e5, 0.5, 0.0), (1e5, 0.3, 2.0), (2.5e4, 0.2, 0.7)];
    let m = Gms {
        elements: elements
            .iter()
            .map(|&(k, w, c)| GmsElement {
                stiffness: k,
                weight: w,
                damping: c,
            })
            .collect(),
        viscous: 0.8,
        ..Gms::default()
    };
    let single = |i: usize| {
        let (k, w, c) = elements[i];
        Gms {
            elements: vec![GmsElement {
                stiffness: k,
                weight: w,
                damping: c,
            }],
            viscous: 0.0,
            ..m.clone()
        }
    };
    let z = [3e-6, -2e-6, 4e-5];
    for v in [0.0, 1e-5, 0.004, -0.02, 0.3] {
        let sum: f64 = (0..3)
            .map(|i| single(i).force(v, &z[i..=i], N))
            .sum::<f64>()
            + 0.8 * v;
        assert!(close(m.force(v, &z, N), sum, 1e-14), "v = {v}");
        let mut d = [0.0; 3];
        m.state_derivative(v, &z, N, &mut d);
        for i in 0..3 {
            let mut di = [0.0];
            single(i).state_derivative(v, &z[i..=i], N, &mut di);
            assert_eq!(d[i], di[0]);
        }
    }
    // Hand values: F = sum k z (+ damping terms) + viscous v; with v = 0 the rates vanish.
    let f0 = 4e5 * 3e-6 - 1e5 * 2e-6 + 2.5e4 * 4e-5;
    assert!(close(m.force(0.0, &z, N), f0, 1e-14));
    let e = 0.5 * (4e5 * 9e-12 + 1e5 * 4e-12 + 2.5e4 * 1.6e-9);
    assert!(close(m.stored_energy(&z, N), e, 1e-14));
    // Steady state: the weights sum to 1, so the Stribeck level plus viscous.
    let v = 0.01;
    let s = 14.5 * (0.2 + 0.1 * EXP_M1);
    assert!(close(m.steady_state(v, N), s + 0.8 * v, 1e-14));
    assert_eq!(m.n_states(), 3);
}

#[test]
fn gms_without_element_damping_never_creates_energy() {
    // F v - d/dt (stored) = sum k z (v - dz/dt) + viscous v^2 >= 0 at every (v, z).
    for sharpness in [1.0, 2.0, 5.0] {
        let m = Gms {
            sharpness,
            ..Gms::default()
        };
        for v in [-0.3, -0.01, -1e-4, 0.0, 2e-6, 0.008, 0.5] {
            for zs in [-3e-5, -1e-6, 0.0, 4e-6, 2e-5, 1e-4] {
                let z = [zs, -0.5 * zs, 2.0 * zs];
                let mut d = [0.0; 3];
                m.state_derivative(v, &z, N, &mut d);
                let stored_rate: f64 = m
                    .elements
                    .iter()
                    .zip(&z)
                    .zip(&d)
                    .map(|((e, zi), di)| e.stiffness * zi * di)
                    .sum();
                let dissipation = m.force(v, &z, N) * v - stored_rate;
                assert!(
                    dissipation >= -1e-15,
                    "m = {sharpness}, v = {v}, z = {zs}: {dissipation}"
                );
            }
        }
    }
}

#[test]
fn gms_is_odd() {
    let element = |stiffness, weight, damping| GmsElement {
        stiffness,
        weight,
        damping,
    };
    let m = Gms {
        elements: vec![element(3e5, 0.6, 5.0), element(2e4, 0.4, 0.0)],
        sharpness: 3.0,
        ..Gms::default()
    };
    for v in VELOCITIES {
        for zs in [0.0, 1e-6, -7e-6, 3e-5, 1e-3] {
            let z = [zs, 0.3 * zs];
            let zn = [-zs, -0.3 * zs];
            assert_eq!(m.force(-v, &zn, N), -m.force(v, &z, N), "v = {v}, z = {zs}");
            let (mut d, mut dn) = ([0.0; 2], [0.0; 2]);
            m.state_derivative(v, &z, N, &mut d);
            m.state_derivative(-v, &zn, N, &mut dn);
            assert_eq!(dn, [-d[0], -d[1]]);
        }
        assert_eq!(m.steady_state(-v, N), -m.steady_state(v, N));
    }
}

#[test]
fn gms_config_per_element_lists_and_scalars() {
    let b = toml_model(
        "type = \"gms\"\nstiffness = [4.0e5, 1.0e5]\nweights = 0.5\nmu_c = 0.25\nmu_s = 0.3",
    )
    .unwrap();
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    let names: Vec<String> = b.model.param_info().into_iter().map(|p| p.name).collect();
    assert_eq!(
        names,
        [
            "k_1",
            "k_2",
            "w_1",
            "w_2",
            "sigma_1",
            "sigma_2",
            "mu_c",
            "mu_s",
            "v_s",
            "delta",
            "sharpness",
            "viscous"
        ]
    );
    assert_eq!(
        b.model.params(),
        [4e5, 1e5, 0.5, 0.5, 0.0, 0.0, 0.25, 0.3, 0.01, 2.0, 2.0, 0.5]
    );
    assert_eq!(b.model.n_states(), 2);
    // `elements` with defaults: geometric stiffnesses, equal weights.
    let b = toml_model("type = \"gms\"\nelements = 4\ndamping = 1.5").unwrap();
    let p = b.model.params();
    assert_eq!(p[..4], [1e5, 1e5 / 3.0, 1e5 / 9.0, 1e5 / 27.0]);
    assert_eq!(p[4..8], [0.25; 4]);
    assert_eq!(p[8..12], [1.5; 4]);
    // The default model: three elements.
    assert_eq!(default_model("gms").unwrap().n_states(), 3);
    // set_params keeps the element count and checks the length.
    let mut m = b.model;
    let q: Vec<f64> = (0..18).map(|i| f64::from(i) + 1.0).collect();
    m.set_params(&q).unwrap();
    assert_eq!(m.params(), q);
    assert!(matches!(
        m.set_params(&q[..17]),
        Err(ModelError::ParamCount {
            expected: 18,
            got: 17,
            ..
        })
    ));
}

#[test]
fn gms_config_errors_name_the_key() {
    for (text, key, needle) in [
        (
            "type = \"gms\"\nelements = 3\nstiffness = [1e5, 2e5]",
            "stiffness",
            "has 2 values but the model has 3 elements",
        ),
        (
            "type = \"gms\"\nstiffness = [1e5, 2e5]\nweights = [0.2, 0.3, 0.5]",
            "weights",
            "(from `stiffness`)",
        ),
        (
            "type = \"gms\"\nelements = 0",
            "elements",
            "1 to 100 elements",
        ),
        ("type = \"gms\"\nweights = []", "weights", "got 0"),
    ] {
        let e = toml_model(text).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(&format!("key `{key}`")), "{text}: {msg}");
        assert!(msg.contains(needle), "{text}: {msg}");
        assert!(!msg.contains('\n'));
    }
    let e = toml_error("type = \"gms\"\nstifness = 1e5");
    assert!(
        e.contains("unknown parameter `stifness`") && e.contains("did you mean `stiffness`"),
        "{e}"
    );
    let e = toml_error("type = \"gms\"\nweights = \"equal\"");
    assert!(
        e.contains("a number (for all elements) or a list of numbers"),
        "{e}"
    );
    let e = toml_model("type = \"gms\"\nstiffness = [1e5, -2.0]").unwrap_err();
    assert!(
        matches!(e, ModelError::OutOfBounds { ref param, .. } if param == "k_2"),
        "{e}"
    );
    // Weights that do not sum to 1 are allowed, with a warning.
    let b = toml_model("type = \"gms\"\nweights = [0.5, 0.7]").unwrap();
    assert_eq!(b.warnings.len(), 1);
    assert!(b.warnings[0].contains("sum to 1.2"), "{:?}", b.warnings);
}

// ---------------------------------------------------------------- expression

fn expr(force: &str, params: &[(&str, f64)]) -> Expression {
    Expression::new(force, params).unwrap()
}

#[test]
fn expression_sign_law_is_exactly_coulomb() {
    for mu in [0.0, 0.13, 0.2, 0.24, 0.7] {
        let c = Coulomb { mu };
        let e = expr("mu * N * sign(v)", &[("mu", mu)]);
        for normal in [0.0, 1.0, N, 123.4] {
            assert_eq!(e.static_limit(normal), c.static_limit(normal));
            for v in VELOCITIES {
                for v in [v, -v] {
                    assert_eq!(e.force(v, &[], normal), c.force(v, &[], normal), "v = {v}");
                    assert_eq!(e.steady_state(v, normal), c.steady_state(v, normal));
                    for dir in [1.0, -1.0] {
                        assert_eq!(
                            e.slip_force(v, dir, normal),
                            c.slip_force(v, dir, normal),
                            "v = {v}, direction {dir}"
                        );
                    }
                }
            }
        }
    }
    // The spellings sgn and signum, and sign(-v), are the same law.
    let c = Coulomb { mu: 0.2 };
    for f in [
        "mu * N * sgn(v)",
        "mu * N * signum(v)",
        "-(mu * N * sign(-v))",
    ] {
        let e = expr(f, &[("mu", 0.2)]);
        assert_eq!(e.static_limit(N), c.static_limit(N), "{f}");
        assert_eq!(
            e.slip_force(0.0, -1.0, N),
            c.slip_force(0.0, -1.0, N),
            "{f}"
        );
        assert_eq!(e.slip_force(1e-17, -1.0, N), -0.2 * N, "{f}");
        assert_eq!(e.force(0.0, &[], N), 0.0);
    }
}

#[test]
fn expression_viscous_and_stribeck_laws_match_the_built_in_models() {
    let vc = ViscousCoulomb {
        mu: 0.2,
        viscous: 3.0,
    };
    let e = expr("mu * N * sign(v) + b * v", &[("mu", 0.2), ("b", 3.0)]);
    let st = Stribeck::default();
    let es = expr(
        "N * (mu_c + (mu_s - mu_c) * exp(-abs(v / v_s)^delta)) * sgn(v) + viscous * v",
        &st.param_info()
            .iter()
            .map(|p| p.name.as_str())
            .zip(st.params())
            .collect::<Vec<_>>(),
    );
    assert_eq!(e.static_limit(N), vc.static_limit(N));
    assert!(close(
        es.static_limit(N).unwrap(),
        st.static_limit(N).unwrap(),
        1e-15
    ));
    for v in VELOCITIES {
        for v in [v, -v] {
            assert_eq!(e.force(v, &[], N), vc.force(v, &[], N));
            assert!(
                close(es.force(v, &[], N), st.force(v, &[], N), 1e-14),
                "v = {v}"
            );
            for dir in [1.0, -1.0] {
                assert_eq!(e.slip_force(v, dir, N), vc.slip_force(v, dir, N));
                assert!(close(
                    es.slip_force(v, dir, N),
                    st.slip_force(v, dir, N),
                    1e-14
                ));
            }
        }
    }
}

#[test]
fn expression_smooth_law_by_hand() {
    let e = expr(
        "mu * N * tanh(v / eps) + b * v",
        &[("mu", 0.2), ("eps", 1e-4), ("b", 0.5)],
    );
    assert_eq!(e.param_names(), ["mu", "eps", "b"]);
    assert!(close(e.force(1e-4, &[], N), 2.9 * TANH_1 + 5e-5, 1e-15));
    assert!(close(e.force(-2e-4, &[], N), -2.9 * TANH_2 - 1e-4, 1e-15));
    assert!(close(e.force(1e-5, &[], N), 2.9 * TANH_0_1 + 5e-6, 1e-15));
    assert_eq!(e.force(0.0, &[], N), 0.0);
    // No sign(v): a smooth law, no static limit, slip_force is the force.
    assert_eq!(e.static_limit(N), None);
    assert!(!e.is_switched());
    assert_eq!(e.slip_force(1e-4, -1.0, N), e.force(1e-4, &[], N));
    // sign(v) makes a switched law; one whose force vanishes at 0+ breaks away at zero force.
    let e2 = expr(
        "mu * N * sign(v) * tanh(abs(v) / eps)",
        &[("mu", 0.2), ("eps", 1e-4)],
    );
    assert!(e2.is_switched());
    assert_eq!(e2.static_limit(N), Some(0.0));
    assert_eq!(e2.slip_force(0.0, -1.0, N), 0.0);
    assert!(close(e2.force(-1e-4, &[], N), -2.9 * TANH_1, 1e-15));
}

#[test]
fn expression_functions_by_hand() {
    let cases: [(&str, f64, f64); 20] = [
        ("sign(v)", 0.0, 0.0),
        ("sgn(v) + sign(-v)", 2.0, 0.0),
        ("sign(v)", -3.0, -1.0),
        ("abs(v)", -2.5, 2.5),
        ("exp(v)", 1.0, std::f64::consts::E),
        ("ln(v)", std::f64::consts::E, 1.0),
        ("log(v)", 1.0, 0.0),
        ("log10(v)", 1000.0, 3.0),
        ("sqrt(v)", 2.25, 1.5),
        ("tanh(v)", 0.5, TANH_0_5),
        ("sin(v)", std::f64::consts::FRAC_PI_2, 1.0),
        ("cos(v)", 0.0, 1.0),
        ("atan(v)", 1.0, std::f64::consts::FRAC_PI_4),
        ("min(v, 2) + max(v, -1)", 3.0, 5.0),
        ("v^2^3", 2.0, 256.0),
        ("-v^2", 3.0, -9.0),
        ("v**-1", 4.0, 0.25),
        ("2 * pi * v", 0.5, std::f64::consts::PI),
        ("1.5e-3 * v + .5 - 2E+1 / 4", 1000.0, -3.0),
        ("(v - 1) * (v + 1) / (v * v - 1)", 7.0, 1.0),
    ];
    for (f, v, expected) in cases {
        let e = expr(f, &[]);
        assert!(
            close(e.force(v, &[], N), expected, 1e-15),
            "{f} at {v}: {}",
            e.force(v, &[], N)
        );
    }
    // N is the normal force.
    assert_eq!(expr("N", &[]).force(1.0, &[], 12.5), 12.5);
}

#[test]
fn expression_params_are_fittable_with_bounds() {
    let b = toml_model(
        r#"
type = "expression"
force = "b * v + mu * N * tanh(v / eps)"
params = { mu = 0.2, eps = 1.0e-4, b = 0.5 }
bounds = { mu = [0, 1], eps = [1e-9, 1e-2] }
units = { mu = "1", eps = "m/s", b = "N s/m" }
"#,
    )
    .unwrap();
    let mut m = b.model;
    // Order of first appearance in the formula.
    let info = m.param_info();
    let names: Vec<&str> = info.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["b", "mu", "eps"]);
    assert_eq!(m.params(), [0.5, 0.2, 1e-4]);
    assert_eq!((info[1].lower, info[1].upper), (0.0, 1.0));
    assert_eq!(
        (info[0].lower, info[0].upper),
        (f64::NEG_INFINITY, f64::INFINITY)
    );
    assert_eq!(info[2].unit, "m/s");
    // set_params changes the law (the fit path).
    m.set_params(&[1.0, 0.3, 2e-4]).unwrap();
    assert!(close(m.force(2e-4, &[], N), 2e-4 + 0.3 * N * TANH_1, 1e-15));
    assert!(matches!(
        m.set_params(&[1.0]),
        Err(ModelError::ParamCount {
            expected: 3,
            got: 1,
            ..
        })
    ));
    // Values outside the given bounds are errors naming the parameter.
    let e = toml_model(
        "type = \"expression\"\nforce = \"mu * N * sign(v)\"\nparams = { mu = 1.5 }\nbounds = { mu = [0, 1] }",
    )
    .unwrap_err();
    assert!(
        matches!(e, ModelError::OutOfBounds { ref param, .. } if param == "mu"),
        "{e}"
    );
    // apply_guess sets a parameter named mu from the energy estimate, inside its bounds.
    let mut m = expr("mu * N * sign(v)", &[("mu", 0.5)]);
    m.apply_guess(&GuessHint {
        mu: 0.21,
        typical_velocity: 0.05,
        normal_force: N,
        stiffness: 1982.0,
        mass: 10.391,
    });
    assert_eq!(m.params(), [0.21]);
}

#[test]
fn expression_parse_errors_point_at_the_column() {
    for (formula, column) in [
        ("mu * N * tanh(v / )", 19),
        ("mu * N * sign(v) +", 19),
        ("mu * N # v", 8),
        ("mu * (N * v", 12),
        ("mu * N) * v", 7),
        ("mu N", 4),
        ("2 * tanh v", 5),
        ("mu * foo(v)", 6),
        ("max(v)", 1),
        ("1e+ * v", 1),
    ] {
        let text = format!("type = \"expression\"\nforce = \"{formula}\"\nparams = {{ mu = 0.2 }}");
        let msg = toml_error(&text);
        assert!(
            msg.contains(&format!("at column {column} of `{formula}`")),
            "{formula}: {msg}"
        );
        assert!(msg.contains("expression model:"), "{msg}");
        assert!(!msg.contains('\n'));
    }
    let e = Expression::new("mu * N * tanh(v / )", &[("mu", 0.2)]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "expression model: unexpected token `)` (expected a number, a variable, a function or `(`) at column 19 of `mu * N * tanh(v / )`"
    );
}

#[test]
fn expression_unknown_and_unused_names_are_errors() {
    let e = Expression::new("mu * N * sign(v) + c * v", &[("mu", 0.2)]).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("unknown variable `c`"), "{msg}");
    assert!(msg.contains("column 20"), "{msg}");
    assert!(msg.contains("known: v, N, mu"), "{msg}");
    for (params, needle) in [
        (
            &[("mu", 0.2), ("b", 1.0)][..],
            "`b` does not appear in the formula",
        ),
        (&[("mu", 0.2), ("v", 1.0)][..], "`v` is reserved"),
        (&[("mu", 0.2), ("tanh", 1.0)][..], "`tanh` is reserved"),
    ] {
        let msg = Expression::new("mu * N * sign(v)", params)
            .unwrap_err()
            .to_string();
        assert!(msg.contains(needle), "{msg}");
        assert!(msg.contains("key `params`"), "{msg}");
    }
    for (extra, key) in [
        ("bounds = { c = [0, 1] }", "bounds"),
        ("bounds = { mu = [1, 0] }", "bounds"),
        ("units = { c = \"N\" }", "units"),
    ] {
        let text = format!(
            "type = \"expression\"\nforce = \"mu * N * sign(v)\"\nparams = {{ mu = 0.2 }}\n{extra}"
        );
        let msg = toml_error(&text);
        assert!(msg.contains(&format!("key `{key}`")), "{msg}");
    }
    let msg = toml_error("type = \"expression\"\nforce = \"v\"\nparam = { mu = 1 }");
    assert!(
        msg.contains("unknown parameter `param`") && msg.contains("did you mean `params`"),
        "{msg}"
    );
}

#[test]
fn expression_default_model_and_listing() {
    let m = default_model("expression").unwrap();
    assert_eq!(m.equation(), "F = mu * N * tanh(v / eps)");
    assert_eq!(m.params(), [0.2, 1e-4]);
    assert!(close(m.force(1e-4, &[], N), 2.9 * TANH_1, 1e-15));
    let l = listings()
        .into_iter()
        .find(|l| l.name == "expression")
        .unwrap();
    assert_eq!(l.parameters.len(), 2);
    assert_eq!(l.parameters[1].unit, "m/s");
    // Overriding a default parameter of the default formula.
    let b = toml_model("type = \"expression\"\nparams = { mu = 0.3 }").unwrap();
    assert_eq!(b.model.params(), [0.3, 1e-4]);
}

#[test]
fn expression_is_clone_send_sync_and_odd() {
    fn assert_traits<T: Clone + Send + Sync + 'static>() {}
    assert_traits::<Expression>();
    assert_traits::<Gms>();
    let e = expr(
        "N * (mu_c + (mu_s - mu_c) * exp(-(v / v_s)^2)) * sign(v) + b * v + d * v^3",
        &[
            ("mu_c", 0.2),
            ("mu_s", 0.3),
            ("v_s", 0.01),
            ("b", 0.5),
            ("d", 0.1),
        ],
    );
    let copy = e.clone();
    let handle = std::thread::spawn(move || copy.force(0.02, &[], N));
    assert_eq!(handle.join().unwrap(), e.force(0.02, &[], N));
    for v in VELOCITIES {
        assert_eq!(e.force(-v, &[], N), -e.force(v, &[], N));
        assert_eq!(e.slip_force(-v, -1.0, N), -e.slip_force(v, 1.0, N));
    }
}

// ---------------------------------------------------------------- serde

#[test]
fn makkar_gms_and_expression_round_trip_through_json_and_toml() {
    let gms = Gms {
        elements: vec![
            GmsElement {
                stiffness: 4.1e5,
                weight: 0.55,
                damping: 1.25,
            },
            GmsElement {
                stiffness: 3.3e4,
                weight: 0.45,
                damping: 0.0,
            },
        ],
        mu_c: 0.21,
        mu_s: 0.33,
        v_s: 0.004,
        delta: 1.5,
        sharpness: 3.0,
        viscous: 0.7,
    };
    let makkar = Makkar {
        g1: 1.1,
        g2: 210.0,
        g3: 19.0,
        g4: 2.8,
        g5: 900.0,
        g6: 0.45,
    };
    let built = toml_model(
        r#"
type = "expression"
force = "mu * N * sign(v) + b * v"
params = { mu = 0.23, b = 0.4 }
bounds = { mu = [0, 2] }
units = { b = "N s/m" }
"#,
    )
    .unwrap();
    let models: Vec<Box<dyn FrictionModel>> = vec![Box::new(gms), Box::new(makkar), built.model];
    for m in models {
        let json = serde_json::to_string(&m).unwrap();
        let back: Box<dyn FrictionModel> = serde_json::from_str(&json).unwrap();
        let text = toml::to_string(&m).unwrap();
        let back_toml: Box<dyn FrictionModel> = toml::from_str(&text).unwrap();
        let built = build_toml(&toml::from_str::<toml::Value>(&text).unwrap()).unwrap();
        for b in [back, back_toml, built.model] {
            assert_eq!(b.name(), m.name());
            assert_eq!(b.params(), m.params(), "{json}\n{text}");
            assert_eq!(b.param_info(), m.param_info());
            assert_eq!(b.equation(), m.equation());
            let z: Vec<f64> = (0..m.n_states()).map(|i| 1e-6 * (i as f64 + 1.0)).collect();
            for v in [0.0, 0.003, -0.2] {
                assert_eq!(b.force(v, &z, N), m.force(v, &z, N));
            }
            assert_eq!(static_limit(b.as_ref(), N), static_limit(m.as_ref(), N));
        }
    }
}
