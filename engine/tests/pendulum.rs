//! A pendulum with Coulomb friction and viscous damping, released at 90 and 135 degrees,
//! against an independent reference: a fixed-step RK4 integration (step 1e-5 s) written here,
//! its turning points located by bisection on the step and the stick decided there by the
//! torque balance |M_g sin q| <= T_c. The records are written as an encoder would give them
//! (angle in degrees, quantised to 0.09 deg, 1 kHz) and read back with
//! `displacement_scale = pi / 180`.

use crate::util::{fit_coulomb_and_properties, rel};
use frictionid_engine::axis::{Axis, Pendulum, Restoring};
use frictionid_engine::data::RecordSource;
use frictionid_engine::identify::{FitResult, OscillatorParam};
use frictionid_engine::{Oscillator, Record};
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::PathBuf;

/// Inertia J [kg m^2], gravity moment M_g [N m], damping c [N m s/rad], Coulomb torque
/// T_c [N m]: small swings have a period of 2 pi sqrt(J / M_g) = 1.26 s.
const J: f64 = 0.02;
const GRAVITY_MOMENT: f64 = 0.5;
const DAMPING: f64 = 0.002;
const COULOMB: f64 = 0.012;
const RATE: f64 = 1000.0;
const DURATION: f64 = 6.0;
/// The encoder's resolution [deg].
const STEP_DEG: f64 = 0.09;

/// One RK4 step of J q'' = -c q' - M_g sin q - T_c d.
fn rk4(q: f64, w: f64, d: f64, h: f64) -> (f64, f64) {
    let acc = |q: f64, w: f64| -(DAMPING * w + GRAVITY_MOMENT * q.sin() + COULOMB * d) / J;
    let (k1q, k1w) = (w, acc(q, w));
    let (k2q, k2w) = (w + 0.5 * h * k1w, acc(q + 0.5 * h * k1q, w + 0.5 * h * k1w));
    let (k3q, k3w) = (w + 0.5 * h * k2w, acc(q + 0.5 * h * k2q, w + 0.5 * h * k2w));
    let (k4q, k4w) = (w + h * k3w, acc(q + h * k3q, w + h * k3w));
    (
        q + h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q),
        w + h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w),
    )
}

/// The reference motion released from rest at `q0` [rad], sampled at `RATE`.
fn reference(q0: f64) -> Vec<(f64, f64)> {
    const H: f64 = 1e-5;
    let (mut q, mut w, mut t) = (q0, 0.0, 0.0);
    let mut d = -(GRAVITY_MOMENT * q0.sin()).signum();
    let mut stuck = false;
    let n = (DURATION * RATE) as usize + 1;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let t_sample = i as f64 / RATE;
        while !stuck && t < t_sample {
            let h = H.min(t_sample - t);
            let (q1, w1) = rk4(q, w, d, h);
            if d * w1 > 0.0 {
                (q, w, t) = (q1, w1, t + h);
                continue;
            }
            // The turning point inside the step: bisect on the step length.
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if d * rk4(q, w, d, mid).1 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            q = rk4(q, w, d, hi).0;
            w = 0.0;
            t += hi;
            let gravity = GRAVITY_MOMENT * q.sin();
            if gravity.abs() <= COULOMB {
                stuck = true;
            } else {
                d = -gravity.signum();
            }
        }
        out.push((t_sample, q));
    }
    out
}

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("frictionid-pendulum-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The reference released at `deg` degrees, written as an encoder's angle in degrees and
/// read back through the record reader.
fn encoder_record(deg: f64) -> Record {
    let q0 = deg.to_radians();
    let mut csv = String::from("time,angle_deg\n");
    for (t, q) in reference(q0) {
        let counts = (q.to_degrees() / STEP_DEG).round();
        let _ = writeln!(csv, "{t:.6},{:.4}", counts * STEP_DEG);
    }
    let dir = scratch();
    let file = format!("pendulum-{deg}.csv");
    std::fs::write(dir.join(&file), csv).expect("written");
    RecordSource {
        file: Some(file),
        x0: Some(q0),
        displacement_column: Some("angle_deg".into()),
        displacement_scale: Some(PI / 180.0),
        ..RecordSource::default()
    }
    .load(&dir)
    .expect("a readable record")
}

fn pendulum(gravity_moment: f64, damping: f64) -> Oscillator {
    Oscillator {
        mass: J,
        damping,
        stiffness: 1.0,
        normal_force: 1.0,
        axis: Axis::Rotary,
        restoring: Restoring::Pendulum(Pendulum { gravity_moment }),
        input_offset: 0.0,
    }
}

fn fit_with(start: &Oscillator, free: Vec<OscillatorParam>, records: &[Record]) -> FitResult {
    fit_coulomb_and_properties(start, 0.02, free, records)
}

#[test]
fn the_pendulum_is_identified_from_encoder_angles_and_the_spring_is_rejected() {
    let records = [encoder_record(90.0), encoder_record(135.0)];
    // The truth's neighbourhood: the gravity moment 10 % high, the damping 40 % low.
    let start = pendulum(1.1 * GRAVITY_MOMENT, 0.6 * DAMPING);
    let free = vec![OscillatorParam::Damping, OscillatorParam::GravityMoment];
    let r = fit_with(&start, free, &records);
    let m_g = r.oscillator.restoring.parameter("gravity_moment");
    let (c, t_c) = (r.oscillator.damping, r.value("mu").unwrap_or(f64::NAN));
    eprintln!(
        "pendulum: M_g {m_g:?} (truth {GRAVITY_MOMENT}), c {c} ({DAMPING}), T_c {t_c} \
         ({COULOMB}); rms {} rad, AIC {}",
        r.rms_residual, r.aic
    );
    assert!(r.converged, "{}", r.termination);
    assert!(
        m_g.is_some_and(|m| rel(m, GRAVITY_MOMENT) < 5e-3),
        "{m_g:?}"
    );
    assert!(rel(c, DAMPING) < 5e-3, "{c}");
    assert!(rel(t_c, COULOMB) < 5e-3, "{t_c}");

    // The linear spring of the small-angle stiffness, its stiffness and damping fitted.
    let spring = Oscillator {
        restoring: Restoring::default(),
        stiffness: GRAVITY_MOMENT,
        ..start
    };
    let free = vec![OscillatorParam::Damping, OscillatorParam::Stiffness];
    let s = fit_with(&spring, free, &records);
    eprintln!(
        "spring: k {} c {} T_c {:?}; rms {} rad, AIC {} (difference {})",
        s.oscillator.stiffness,
        s.oscillator.damping,
        s.value("mu"),
        s.rms_residual,
        s.aic,
        s.aic - r.aic
    );
    assert!(s.rms_residual > 5.0 * r.rms_residual);
    assert!(s.aic - r.aic > 1000.0, "AIC {} vs {}", s.aic, r.aic);
}

#[test]
fn an_angle_in_degrees_read_as_radians_is_refused_naming_the_record_and_the_scale() {
    let q0 = 90f64.to_radians();
    let mut csv = String::from("time,angle_deg\n");
    for (t, q) in reference(q0) {
        let _ = writeln!(csv, "{t:.6},{:.4}", q.to_degrees());
    }
    let dir = scratch();
    std::fs::write(dir.join("degrees.csv"), csv).expect("written");
    let source = RecordSource {
        file: Some("degrees.csv".into()),
        x0: Some(q0),
        displacement_column: Some("angle_deg".into()),
        ..RecordSource::default()
    };
    let truth = pendulum(GRAVITY_MOMENT, DAMPING);
    let e = source
        .load_checked(&dir, &truth)
        .expect_err("degrees read as radians");
    let message = e.to_string();
    eprintln!("{message}");
    assert!(message.starts_with("degrees.csv: "), "{message}");
    assert!(
        message.contains("set displacement_scale = 0.0174533"),
        "{message}"
    );
    assert!(!message.contains('\n'));
    // Read in radians, the same record passes.
    let radians = RecordSource {
        displacement_scale: Some(PI / 180.0),
        ..source
    };
    assert!(radians.load_checked(&dir, &truth).is_ok());
}
