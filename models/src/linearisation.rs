//! Where a law's partial derivatives are written ([`Linearisation`]) and the steps of their
//! finite differences. Plain values: this module imports nothing of the crate.

/// Where `Jacobians::linearisation` writes (n_states x n_states row-major, then n_states and
/// n_states entries).
pub struct Linearisation<'a> {
    /// d(dz_i)/dz_j, row-major.
    pub dz_dz: &'a mut [f64],
    /// d(dz_i)/dv.
    pub dz_dv: &'a mut [f64],
    /// dF/dz_j.
    pub df_dz: &'a mut [f64],
}

/// cbrt(f64::EPSILON), the relative step of central differences (a constant: `cbrt` is not
/// const-evaluated, and it was 4 % of a GMS fit's time).
pub const CBRT_EPSILON: f64 = 6.055_454_452_393_339_5e-6;

/// Smallest state magnitude the finite-difference step in a state scales with (bristle
/// deflections are often 1e-7..1e-5 m).
const FD_STATE_FLOOR: f64 = 1e-6;

/// Smallest velocity magnitude the finite-difference step in v scales with [m/s].
const FD_VELOCITY_FLOOR: f64 = 1e-6;

/// The central-difference step in state `z_j`: cbrt(eps) max(|z_j|, 1e-6).
#[inline]
pub fn state_step(z_j: f64) -> f64 {
    CBRT_EPSILON * z_j.abs().max(FD_STATE_FLOOR)
}

/// A finite-difference step in the velocity that never crosses v = 0 (where |v| and sgn(v)
/// kink): `(width, upper, lower)` with width = upper - lower. Central around v where the step
/// fits on v's side of zero, one-sided away from zero otherwise (towards +v at v = 0).
pub fn velocity_step(v: f64) -> (f64, f64, f64) {
    let step = CBRT_EPSILON * v.abs().max(FD_VELOCITY_FLOOR);
    if step < v.abs() {
        (2.0 * step, v + step, v - step)
    } else if v < 0.0 {
        (step, v, v - step)
    } else {
        (step, v + step, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_difference_step_constant_is_the_cube_root_of_epsilon() {
        assert_eq!(CBRT_EPSILON, f64::EPSILON.cbrt());
    }
}
