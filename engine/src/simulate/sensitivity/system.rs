//! The augmented equation of motion [y, s_1, ..., s_n]: the states and, for each parameter,
//! s_j' = J s_j + df/dp_j.

use super::super::dynamics::{Dynamics, Law};
use super::super::stepper::OdeSystem;
use super::SensitivityParam;
use frictionid_models::ParamGradients;
use std::cell::RefCell;

/// The direct terms df/dp of each parameter: what they need from the law and the oscillator.
pub(super) struct DirectTerms<'a> {
    params: Vec<SensitivityParam>,
    /// The law's parameter gradients (when a law parameter is among `params`).
    gradients: Option<&'a dyn ParamGradients>,
    /// The law's parameter count.
    n_model: usize,
}

impl<'a> DirectTerms<'a> {
    /// The terms of `params` for `dynamics` starting from `y0`; `None` where one of them has
    /// no derivative (a law without gradients, a states' rate without them, the normal force,
    /// a restoring-law property whose balance column is not its exact derivative).
    pub(super) fn new(
        dynamics: &Dynamics<'a>,
        params: &[SensitivityParam],
        y0: &[f64],
    ) -> Option<Self> {
        let n_model = dynamics.model.params().len();
        let mut gradients = None;
        for &p in params {
            match p {
                SensitivityParam::Model(i) => {
                    let g = dynamics.model.param_gradients()?;
                    if i >= n_model || !rate_gradient_given(dynamics, g, y0, n_model) {
                        return None;
                    }
                    gradients = Some(g);
                }
                SensitivityParam::Property(q) => {
                    if !q.balance_column_exact(&dynamics.osc) {
                        return None;
                    }
                }
                SensitivityParam::StartDisplacement => {}
            }
        }
        Some(Self {
            params: params.to_vec(),
            gradients,
            n_model,
        })
    }

    /// The parameters, in order.
    pub(super) fn params(&self) -> &[SensitivityParam] {
        &self.params
    }
}

/// Whether the law's states' rate has its parameter gradient (a law without states needs
/// none).
fn rate_gradient_given(
    dynamics: &Dynamics<'_>,
    gradients: &dyn ParamGradients,
    y0: &[f64],
    n_model: usize,
) -> bool {
    let Law::Dynamic { .. } = dynamics.law else {
        return true;
    };
    let (v, z) = (
        y0.get(1).copied().unwrap_or(0.0),
        y0.get(2..).unwrap_or(&[]),
    );
    let mut probe = vec![0.0; z.len() * n_model];
    gradients.state_param_gradient(v, z, dynamics.normal, &mut probe)
}

/// Scratch of one right-hand side, and of the Jacobian's differences.
#[derive(Default)]
struct Scratch {
    jac: Vec<f64>,
    force: Vec<f64>,
    rate: Vec<f64>,
    direct: Vec<f64>,
    probe: Vec<f64>,
    base_jac: Vec<f64>,
    base_direct: Vec<f64>,
}

/// The augmented system of one segment (slip direction `dir`).
pub(super) struct Augmented<'a, 'b> {
    pub dynamics: Dynamics<'a>,
    pub dir: f64,
    pub terms: &'b DirectTerms<'a>,
    /// Each state's typical size, which scales its difference step in the Jacobian's
    /// derivatives of the sensitivities' rates ([`OdeSystem::jacobian`]); empty where only
    /// the right-hand side is asked for (the explicit stepper).
    typical: &'b [f64],
    scratch: RefCell<Scratch>,
}

impl<'a, 'b> Augmented<'a, 'b> {
    pub(super) fn new(
        dynamics: Dynamics<'a>,
        dir: f64,
        terms: &'b DirectTerms<'a>,
        typical: &'b [f64],
    ) -> Self {
        Self {
            dynamics,
            dir,
            terms,
            typical,
            scratch: RefCell::new(Scratch::default()),
        }
    }

    /// The states' Jacobian J and the direct terms df/dp_j at the states `state`, left in
    /// the scratch.
    fn jacobian_and_direct_terms(&self, t: f64, state: &[f64], scratch: &mut Scratch) {
        let n = state.len();
        scratch.jac.resize(n * n, 0.0);
        self.dynamics.jacobian(t, state, self.dir, &mut scratch.jac);
        self.direct_terms(t, state, scratch);
    }

    /// The states' dimension n of y = [x, v, z...].
    pub(super) fn n(&self) -> usize {
        2 + self.dynamics.model.n_states()
    }

    /// Writes df/dp_j at (t, y) into column j of `out` (n x n_params, column-major).
    fn direct_terms(&self, t: f64, y: &[f64], scratch: &mut Scratch) {
        let n = y.len();
        let [x, v, z @ ..] = y else {
            return;
        };
        let Scratch {
            force,
            rate,
            direct,
            ..
        } = scratch;
        direct.clear();
        direct.resize(n * self.terms.params.len(), 0.0);
        let mass = self.dynamics.osc.mass;
        if let Some(g) = self.terms.gradients {
            // A switched law slips in its segment's direction even at v = 0 (as its force).
            let v_law = match self.dynamics.law {
                Law::Switched { .. } if self.dir * v <= 0.0 => self.dir * f64::MIN_POSITIVE,
                _ => *v,
            };
            force.resize(self.terms.n_model, 0.0);
            g.force_param_gradient(v_law, z, self.dynamics.normal, force);
            if !z.is_empty() {
                rate.resize(z.len() * self.terms.n_model, 0.0);
                g.state_param_gradient(*v, z, self.dynamics.normal, rate);
            }
        }
        let accel = || {
            let f = self.dynamics.force(t, *x, *v, z, self.dir);
            self.dynamics.accel(t, *x, *v, f)
        };
        for (j, p) in self.terms.params.iter().enumerate() {
            let col = &mut direct[j * n..(j + 1) * n];
            match *p {
                SensitivityParam::Model(i) => {
                    col[1] = -force[i] / mass;
                    for (k, c) in col[2..].iter_mut().enumerate() {
                        *c = rate[k * self.terms.n_model + i];
                    }
                }
                SensitivityParam::Property(q) => {
                    col[1] = -q.balance_column(accel(), *v, *x) / mass;
                }
                SensitivityParam::StartDisplacement => {}
            }
        }
    }
}

impl Augmented<'_, '_> {
    /// Writes d(df/dp_j)/dt at fixed states into each parameter's block of `d_sens` (n
    /// components per parameter), given the acceleration's explicit rate `accel_rate`
    /// (d(x'')/dt at fixed y). Only an oscillator property's balance column can read the
    /// time, through the acceleration: the mass's d(x'')/dm = -x''/m moves by
    /// -accel_rate / m. The law's force and states' rate gradients do not read it (a law
    /// that reads conditions has no augmented run).
    fn direct_terms_time_rates(&self, accel_rate: f64, d_sens: &mut [f64]) {
        let n = self.n();
        let mass = self.dynamics.osc.mass;
        for (col, p) in d_sens.chunks_exact_mut(n).zip(&self.terms.params) {
            col.fill(0.0);
            if let SensitivityParam::Property(q) = *p {
                col[1] = -q.balance_column_acceleration_slope() * accel_rate / mass;
            }
        }
    }
}

impl OdeSystem for Augmented<'_, '_> {
    /// The states' df/dt ([`Dynamics::time_derivative`]) and, for each s_j' = J s_j +
    /// df/dp_j, the rate of its direct terms: J does not read the time (the input enters
    /// the acceleration additively), the mass's direct term does through x''.
    fn time_derivative(&self, t: f64, y: &[f64], dfdt: &mut [f64]) -> bool {
        let n = self.n();
        let (state, d_state) = (&y[..n], &mut dfdt[..n]);
        if !self.dynamics.time_derivative(t, state, self.dir, d_state) {
            return false;
        }
        let accel_rate = d_state[1];
        self.direct_terms_time_rates(accel_rate, &mut dfdt[n..]);
        true
    }

    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.n();
        let (state, sens) = y.split_at(n);
        let (d_state, d_sens) = dy.split_at_mut(n);
        self.dynamics.rhs(t, state, d_state, self.dir);
        let mut scratch = self.scratch.borrow_mut();
        self.jacobian_and_direct_terms(t, state, &mut scratch);
        let Scratch { jac, direct, .. } = &*scratch;
        match n {
            2 => sensitivity_rates::<2>(jac, sens, direct, d_sens),
            3 => sensitivity_rates::<3>(jac, sens, direct, d_sens),
            4 => sensitivity_rates::<4>(jac, sens, direct, d_sens),
            5 => sensitivity_rates::<5>(jac, sens, direct, d_sens),
            _ => general_sensitivity_rates(n, jac, sens, direct, d_sens),
        }
    }

    /// Block lower triangular, as [`Rodas4::block_triangular`] solves it: the states'
    /// Jacobian J on every diagonal block, and below it the derivative of each s_j' in the
    /// states, H_j = (dJ/dy) s_j + d(df/dp_j)/dy. The derivatives of J and of the direct
    /// terms are forward differences (one Jacobian and one set of direct terms per state)
    /// at steps of sqrt(eps) times the state's size or its typical size, whichever is
    /// larger, the velocity's in the segment's direction. They are taken of J and of the
    /// terms apart, not of the rates J s_j + df/dp_j, whose large and nearly unchanged J s_j
    /// would leave rounding errors of the step's order in the difference (entries of J that
    /// do not move give exact zeros). H_j enters only the stiff stepper's linear systems,
    /// not the rates it integrates.
    ///
    /// [`Rodas4::block_triangular`]: super::super::Rodas4::block_triangular
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        let n = self.n();
        let dim = y.len();
        let (state, sens) = y.split_at(n);
        jac.fill(0.0);
        let mut guard = self.scratch.borrow_mut();
        let scratch = &mut *guard;
        self.jacobian_and_direct_terms(t, state, scratch);
        for block in 0..dim / n {
            for r in 0..n {
                let row = (block * n + r) * dim + block * n;
                jac[row..row + n].copy_from_slice(&scratch.jac[r * n..(r + 1) * n]);
            }
        }
        let base_jac = std::mem::take(&mut scratch.base_jac);
        let base_direct = std::mem::take(&mut scratch.base_direct);
        let (base_jac, base_direct) = (
            refill(base_jac, &scratch.jac),
            refill(base_direct, &scratch.direct),
        );
        let mut probe = std::mem::take(&mut scratch.probe);
        for c in 0..n {
            let typical = self.typical.get(c).copied().unwrap_or(0.0);
            let size = f64::EPSILON.sqrt() * state[c].abs().max(typical).max(f64::MIN_POSITIVE);
            // The velocity moves on in the segment's direction: from a turning point (v = 0)
            // a step against it would cross the kink of the law in v.
            let step = if c == 1 { self.dir * size } else { size };
            probe.clear();
            probe.extend_from_slice(state);
            probe[c] += step;
            self.jacobian_and_direct_terms(t, &probe, scratch);
            for (j, s) in sens.chunks_exact(n).enumerate() {
                for i in 0..n {
                    let moved = &scratch.jac[i * n..(i + 1) * n];
                    let held = &base_jac[i * n..(i + 1) * n];
                    let d_jac_s: f64 = moved
                        .iter()
                        .zip(held)
                        .zip(s)
                        .map(|((a, b), sk)| (a - b) * sk)
                        .sum();
                    let d_direct = scratch.direct[j * n + i] - base_direct[j * n + i];
                    jac[((j + 1) * n + i) * dim + c] = (d_jac_s + d_direct) / step;
                }
            }
        }
        scratch.probe = probe;
        scratch.base_jac = base_jac;
        scratch.base_direct = base_direct;
    }
}

/// `buf` holding a copy of `from`.
fn refill(mut buf: Vec<f64>, from: &[f64]) -> Vec<f64> {
    buf.clear();
    buf.extend_from_slice(from);
    buf
}

/// s_j' = df/dp_j + J s_j for every parameter j, for states of any dimension `n`.
fn general_sensitivity_rates(
    n: usize,
    jac: &[f64],
    sens: &[f64],
    direct: &[f64],
    d_sens: &mut [f64],
) {
    for ((s, ds), d) in sens
        .chunks_exact(n)
        .zip(d_sens.chunks_exact_mut(n))
        .zip(direct.chunks_exact(n))
    {
        for (i, (o, &di)) in ds.iter_mut().zip(d).enumerate() {
            let row = &jac[i * n..(i + 1) * n];
            *o = di + row.iter().zip(s).map(|(a, b)| a * b).sum::<f64>();
        }
    }
}

/// s_j' = df/dp_j + J s_j for every parameter j, with the states' dimension `N` known to the
/// compiler (the rows of J held in registers across the parameters): each rate is the same
/// sum in the same order as the general size's, so the same bits, and LuGre's augmented run
/// with its six parameters over 2 s of the 22 mm release takes a seventh less time (2.60 ms
/// to 2.27 ms).
fn sensitivity_rates<const N: usize>(
    jac: &[f64],
    sens: &[f64],
    direct: &[f64],
    d_sens: &mut [f64],
) {
    let mut rows = [[0.0; N]; N];
    for (i, row) in rows.iter_mut().enumerate() {
        for (k, a) in row.iter_mut().enumerate() {
            *a = jac[i * N + k];
        }
    }
    for ((s, ds), d) in sens
        .chunks_exact(N)
        .zip(d_sens.chunks_exact_mut(N))
        .zip(direct.chunks_exact(N))
    {
        for ((o, &di), row) in ds.iter_mut().zip(d).zip(&rows) {
            *o = di + row.iter().zip(s).map(|(a, b)| a * b).sum::<f64>();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{general_sensitivity_rates, sensitivity_rates};

    /// The rates of every parameter's sensitivity as the general size computes them.
    fn general(n: usize, jac: &[f64], sens: &[f64], direct: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; sens.len()];
        general_sensitivity_rates(n, jac, sens, direct, &mut out);
        out
    }

    /// Values of every sign and many magnitudes, reproducible.
    fn values(len: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..len)
            .map(|_| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
                (unit - 0.5) * 10f64.powi((state % 17) as i32 - 8)
            })
            .collect()
    }

    fn check<const N: usize>(params: usize) {
        let jac = values(N * N, 1 + N as u64);
        let sens = values(N * params, 2 + N as u64);
        let direct = values(N * params, 3 + N as u64);
        let mut fixed = vec![f64::NAN; sens.len()];
        sensitivity_rates::<N>(&jac, &sens, &direct, &mut fixed);
        let expected = general(N, &jac, &sens, &direct);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&fixed), bits(&expected), "size {N}");
    }

    #[test]
    fn the_fixed_size_rates_equal_the_general_ones_to_the_bit() {
        check::<2>(3);
        check::<3>(7);
        check::<4>(5);
        check::<5>(9);
    }

    #[test]
    fn a_wrong_rate_is_told_apart() {
        let jac = values(9, 4);
        let sens = values(6, 5);
        let direct = values(6, 6);
        let mut fixed = vec![0.0; 6];
        sensitivity_rates::<3>(&jac, &sens, &direct, &mut fixed);
        // Without the direct terms the rates differ: the comparison above can fail.
        assert_ne!(fixed, general(3, &jac, &sens, &[0.0; 6]));
    }
}
