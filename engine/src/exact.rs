//! The exact piecewise solution of the Coulomb oscillator (free vibration from rest).
//!
//! Each half-cycle, m x'' + c x' + k x = -F d with d = +1 or -1 the sliding direction, is
//! damped harmonic motion about the shifted centre x_c = -d F / k, starting from rest. With
//! u = x - x_c, omega_n = sqrt(k/m), zeta = c / (2 sqrt(k m)), omega_d = omega_n sqrt(1 - zeta^2):
//!
//!   u(t) = u0 exp(-zeta omega_n t) (cos(omega_d t) + zeta omega_n / omega_d sin(omega_d t))
//!   v(t) = -u0 omega_n^2 / omega_d exp(-zeta omega_n t) sin(omega_d t)
//!
//! The half-cycle ends at rest after pi / omega_d. The mass sticks for good at a turning point
//! where |k x| <= F. This is the test oracle of the engine and the energy analysis.

use crate::error::EngineError;
use crate::oscillator::Oscillator;

/// Samples of the exact solution and its turning points.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactCoulomb {
    /// Sample times [s].
    pub time: Vec<f64>,
    /// Displacement [m].
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Acceleration [m/s^2] (0 once at rest).
    pub a: Vec<f64>,
    /// Time at which the mass sticks for good.
    pub rest_time: f64,
    /// Displacement at rest.
    pub final_displacement: f64,
    /// Times of the turning points (zero velocity), excluding t = 0.
    pub turning_times: Vec<f64>,
    /// Displacements at the turning points.
    pub turning_displacements: Vec<f64>,
}

impl ExactCoulomb {
    /// Number of half-cycles (slip phases) before rest.
    pub fn half_cycles(&self) -> usize {
        self.turning_times.len()
    }
}

/// The exact solution from rest at `x0` with Coulomb force `friction` = mu N, at `times`
/// (which must start at or after 0). Requires an underdamped oscillator (zeta < 1).
pub fn coulomb_free_vibration(
    osc: &Oscillator,
    friction: f64,
    x0: f64,
    times: &[f64],
) -> Result<ExactCoulomb, EngineError> {
    osc.validate()?;
    let zeta = osc.damping_ratio();
    if zeta >= 1.0 {
        return Err(EngineError::InvalidInput(
            "the exact Coulomb solution needs an underdamped oscillator (zeta < 1)".into(),
        ));
    }
    if !(friction.is_finite() && friction >= 0.0 && x0.is_finite()) {
        return Err(EngineError::InvalidInput(
            "friction must be >= 0 and x0 finite".into(),
        ));
    }
    let (k, m) = (osc.stiffness, osc.mass);
    let wn = osc.omega_n();
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let sigma = zeta * wn;
    let half = std::f64::consts::PI / wd;

    // Turning points: start times, start displacements and directions of every slip phase.
    let mut phases: Vec<(f64, f64, f64)> = Vec::new();
    let (mut t, mut x) = (0.0, x0);
    let mut turning_times = Vec::new();
    let mut turning_displacements = Vec::new();
    while (k * x).abs() > friction {
        let d = -x.signum();
        phases.push((t, x, d));
        let xc = -d * friction / k;
        let u0 = x - xc;
        x = xc - u0 * (-sigma * half).exp();
        t += half;
        turning_times.push(t);
        turning_displacements.push(x);
    }
    let (rest_time, final_displacement) = (t, x);

    let n = times.len();
    let (mut xs, mut vs, mut as_) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for (i, &ti) in times.iter().enumerate() {
        let phase = phases.iter().rev().find(|p| ti >= p.0);
        match phase {
            Some(&(ts, xs0, d)) if ti < rest_time => {
                let tau = ti - ts;
                let xc = -d * friction / k;
                let u0 = xs0 - xc;
                let e = (-sigma * tau).exp();
                let (s, c) = (wd * tau).sin_cos();
                let u = u0 * e * (c + sigma / wd * s);
                let v = -u0 * wn * wn / wd * e * s;
                xs[i] = xc + u;
                vs[i] = v;
                as_[i] = -(osc.damping * v + k * xs[i] + d * friction) / m;
            }
            _ => {
                xs[i] = if ti >= rest_time {
                    final_displacement
                } else {
                    x0
                };
            }
        }
    }
    Ok(ExactCoulomb {
        time: times.to_vec(),
        x: xs,
        v: vs,
        a: as_,
        turning_times,
        turning_displacements,
        rest_time,
        final_displacement,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's Figs. 2 and 3: from 140 mm the mass stops at -9.297 mm after 6
    /// half-cycles; from 110 mm at +10.529 mm after 4.
    #[test]
    fn reproduces_the_papers_rest_positions() {
        let mut osc = Oscillator::fmm();
        osc.normal_force = osc.mass * 9.81;
        let f = 0.24 * osc.normal_force;
        let a = coulomb_free_vibration(&osc, f, 0.140, &[]).unwrap();
        assert_eq!(a.half_cycles(), 6);
        assert!((a.final_displacement * 1e3 + 9.297).abs() < 5e-4);
        let b = coulomb_free_vibration(&osc, f, 0.110, &[]).unwrap();
        assert_eq!(b.half_cycles(), 4);
        assert!((b.final_displacement * 1e3 - 10.529).abs() < 5e-4);
    }

    /// The samples satisfy the equation of motion and the energy balance of one half-cycle.
    #[test]
    fn samples_satisfy_the_equation_of_motion() {
        let osc = Oscillator::fmm();
        let f = 0.24 * osc.normal_force;
        let h = 1e-6;
        let ts = [0.1, 0.3, 0.55];
        let p: Vec<f64> = ts.iter().flat_map(|&t| [t - h, t, t + h]).collect();
        let s = coulomb_free_vibration(&osc, f, 0.022, &p).unwrap();
        for j in 0..ts.len() {
            let (i0, i1, i2) = (3 * j, 3 * j + 1, 3 * j + 2);
            let v_fd = (s.x[i2] - s.x[i0]) / (2.0 * h);
            let a_fd = (s.v[i2] - s.v[i0]) / (2.0 * h);
            assert!((v_fd - s.v[i1]).abs() < 1e-8, "v {v_fd} vs {}", s.v[i1]);
            assert!((a_fd - s.a[i1]).abs() < 1e-5, "a {a_fd} vs {}", s.a[i1]);
        }
    }
}
