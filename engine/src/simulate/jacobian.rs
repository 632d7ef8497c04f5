//! The Jacobian of the equation of motion y = [x, v, z...] for the stiff stepper.
//!
//! With F(v, z) the friction force and dz/dt = h(v, z) the state law,
//!
//! ```text
//!       | 0        1                 0            |
//! J  =  | -k/m    -(c + dF/dv)/m    -(dF/dz)/m    |
//!       | 0        dh/dv             dh/dz        |
//! ```
//!
//! dh/dz is the model's `state_jacobian`, dF/dv and dF/dz its `force_gradient` and dh/dv its
//! `state_velocity_derivative` (analytic for the built-in dynamic models, finite differences
//! by default), all three from one call of its `linearisation`. For static laws only the
//! 2 x 2 mechanics remain, with d(slip_force)/dv taken by finite differences. A law that
//! reads the displacement (a position ripple) adds dF/dx to -k/m, by finite differences too.

use super::{Dynamics, Law};
use frictionid_models::linearisation::velocity_step;
use frictionid_models::{Derivatives, Linearisation};

impl Dynamics<'_> {
    /// Writes the Jacobian of [`Dynamics::rhs`] at `y` in slip direction `dir`, row-major,
    /// into `jac` (len(y)^2 entries). Allocates nothing beyond what the model's derivative
    /// methods do, up to [`STACK_STATES`] internal states.
    pub(crate) fn jacobian(&self, t: f64, y: &[f64], dir: f64, jac: &mut [f64]) {
        let n = y.len();
        let ([x, v, z @ ..], true) = (y, jac.len() == n * n) else {
            return;
        };
        // At a segment's start v = 0 exactly: differentiate on the side of the slip direction
        // (where |v| and sgn(v) have their one-sided derivatives), mirror-symmetrically.
        let v = if *v == 0.0 {
            dir * f64::MIN_POSITIVE
        } else {
            *v
        };
        let df_dv = match self.law {
            Law::Dynamic { derivatives, .. } => self.state_blocks(&derivatives, v, z, jac),
            _ => self.slip_slope(t, *x, v, dir),
        };
        if let Some(row0) = jac.get_mut(..n) {
            row0.fill(0.0);
            row0[1] = 1.0;
        }
        let df_dx = self.position_slope(t, *x, v, z, dir);
        jac[n] = -(self.restoring_stiffness(*x) + df_dx) / self.osc.mass;
        jac[n + 1] = -(self.osc.damping + df_dv) / self.osc.mass;
    }

    /// d(slip_force)/dv of a static law in direction `dir`.
    fn slip_slope(&self, t: f64, x: f64, v: f64, dir: f64) -> f64 {
        let (width, hi, lo) = velocity_step(v);
        let force = |u: f64| self.slip_force(t, x, u, dir);
        (force(hi) - force(lo)) / width
    }

    /// dF/dx at fixed v and states, by central differences: 0 unless the law reads the
    /// displacement.
    fn position_slope(&self, t: f64, x: f64, v: f64, z: &[f64], dir: f64) -> f64 {
        if !self.conditions.is_some_and(|c| c.reads_displacement()) {
            return 0.0;
        }
        let h = 1e-6 * x.abs().max(1e-6);
        let force = |s: f64| self.force(t, s, v, z, dir);
        (force(x + h) - force(x - h)) / (2.0 * h)
    }

    /// Fills rows 1 (dF/dz, scaled by -1/m) and 2.. (dh/dv, dh/dz) of a dynamic model; rows
    /// 0 and the first two entries of row 1 are left for the caller. Returns dF/dv.
    ///
    /// One call of the model's `linearisation` (LuGre shares its Stribeck exponential between
    /// the three derivatives) into scratch on the stack for up to [`STACK_STATES`] states (a
    /// heap buffer beyond), then each entry into its block.
    fn state_blocks(
        &self,
        derivatives: &Derivatives<'_>,
        v: f64,
        z: &[f64],
        jac: &mut [f64],
    ) -> f64 {
        let nz = z.len();
        let n = nz + 2;
        let need = nz * nz + 2 * nz;
        let mut stack = [0.0; STACK_SCRATCH];
        let mut heap = Vec::new();
        let scratch = if need <= STACK_SCRATCH {
            &mut stack[..need]
        } else {
            heap.resize(need, 0.0);
            &mut heap[..]
        };
        let (dz_dz, rest) = scratch.split_at_mut(nz * nz);
        let (dz_dv, df_dz) = rest.split_at_mut(nz);
        let out = Linearisation {
            dz_dz,
            dz_dv,
            df_dz,
        };
        let df_dv = derivatives.linearisation(v, z, self.normal, out);
        let (dz_dz, rest) = scratch.split_at(nz * nz);
        let (dz_dv, df_dz) = rest.split_at(nz);
        for i in 0..nz {
            let row = &mut jac[(2 + i) * n..(3 + i) * n];
            row[0] = 0.0;
            row[1] = dz_dv[i];
            row[2..].copy_from_slice(&dz_dz[i * nz..(i + 1) * nz]);
        }
        for (d, &f) in jac[n + 2..2 * n].iter_mut().zip(df_dz) {
            *d = f / -self.osc.mass;
        }
        df_dv
    }
}

/// States whose derivatives fit the stack scratch of [`Dynamics::jacobian`] (7: 49 + 14 entries).
const STACK_STATES: usize = 7;

/// Entries of that scratch.
const STACK_SCRATCH: usize = STACK_STATES * STACK_STATES + 2 * STACK_STATES;

#[cfg(test)]
mod tests {
    use super::super::Dynamics;
    use frictionid_models::{build_json, names};

    /// Central differences of the whole right-hand side, column by column.
    fn numeric_jacobian(d: &Dynamics<'_>, y: &[f64], dir: f64) -> Vec<f64> {
        let n = y.len();
        let mut jac = vec![0.0; n * n];
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let step = 1e-6 * y[j].abs().max(1e-3);
            let mut probe = y.to_vec();
            probe[j] = y[j] + step;
            d.rhs(0.0, &probe, &mut plus, dir);
            probe[j] = y[j] - step;
            d.rhs(0.0, &probe, &mut minus, dir);
            for i in 0..n {
                jac[i * n + j] = (plus[i] - minus[i]) / (2.0 * step);
            }
        }
        jac
    }

    /// A law that reads x: dF/dx joins the spring's -k/m in the Jacobian.
    #[test]
    fn a_position_ripple_s_slope_in_x_is_in_the_jacobian() {
        use super::super::conditions::BoundConditions;
        let ripple = frictionid_models::PositionRipple {
            mu: 0.2,
            ripple: 0.05,
            period: 0.01,
            phase: 0.3,
            viscous: 2.0,
        };
        let bound = BoundConditions::bind(&ripple, None, None)
            .expect("x is given")
            .expect("the law reads x");
        let d = Dynamics::new(&crate::Oscillator::fmm(), &ripple)
            .expect("a switched law")
            .reading(Some(&bound));
        for (x, v, dir) in [(0.01, 0.05, 1.0), (-0.003, -0.02, -1.0)] {
            let y = [x, v];
            let mut jac = [f64::NAN; 4];
            d.jacobian(0.0, &y, dir, &mut jac);
            let num = numeric_jacobian(&d, &y, dir);
            let spring = -crate::Oscillator::fmm().stiffness / crate::Oscillator::fmm().mass;
            assert!(
                (jac[2] - spring).abs() > 1e-3,
                "the ripple has a slope in x"
            );
            for (a, b) in jac.iter().zip(&num) {
                assert!((a - b).abs() <= 1e-5 * (1.0 + b.abs()), "{a} vs {b}");
            }
        }
    }

    #[test]
    fn the_jacobian_matches_finite_differences_of_the_rhs_for_every_built_in_model() {
        for name in names() {
            let Ok(built) = build_json(&serde_json::json!({ "type": name })) else {
                continue;
            };
            let model = built.model;
            let Ok(d) = Dynamics::new(&crate::Oscillator::fmm(), model.as_ref()) else {
                continue;
            };
            let nz = model.n_states();
            for (v, dir) in [(0.05, 1.0), (-0.02, -1.0), (3e-3, 1.0)] {
                let mut y = vec![0.01, v];
                // Deflections of a fraction of the sliding limit (loading and unloading).
                y.extend(
                    (0..nz).map(|i| 2e-7 * (1.0 + i as f64) * if i % 2 == 0 { 1.0 } else { -1.0 }),
                );
                let n = y.len();
                let mut jac = vec![f64::NAN; n * n];
                d.jacobian(0.0, &y, dir, &mut jac);
                let num = numeric_jacobian(&d, &y, dir);
                for (k, (a, b)) in jac.iter().zip(&num).enumerate() {
                    let scale = 1.0 + b.abs().max(a.abs());
                    assert!(
                        (a - b).abs() <= 1e-5 * scale,
                        "{name} v {v}: entry ({}, {}) analytic {a} vs numeric {b}",
                        k / n,
                        k % n
                    );
                }
            }
        }
    }
}
