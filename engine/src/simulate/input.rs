//! A measured input u(t) (a force or a torque) that drives the axis: linear between its
//! samples, held at its first and last values beyond them.

use crate::error::EngineError;

/// u(t) from samples (t_i, u_i), t strictly increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    time: Vec<f64>,
    value: Vec<f64>,
}

impl Input {
    /// The input sampled at `time` (strictly increasing, finite) with `value` (finite, as
    /// many).
    pub fn new(time: Vec<f64>, value: Vec<f64>) -> Result<Self, EngineError> {
        let bad = |what: String| Err(EngineError::InvalidInput(format!("input force: {what}")));
        if time.len() != value.len() {
            return bad(format!("{} times but {} values", time.len(), value.len()));
        }
        if time.is_empty() {
            return bad("no samples".into());
        }
        if let Some(i) = value.iter().position(|u| !u.is_finite()) {
            return bad(format!("sample {i} is not finite ({})", value[i]));
        }
        if let Some(i) = time.iter().position(|t| !t.is_finite()) {
            return bad(format!("time {i} is not finite"));
        }
        if let Some(i) = time.windows(2).position(|w| w[1] <= w[0]) {
            return bad(format!("times not increasing at sample {}", i + 1));
        }
        Ok(Self { time, value })
    }

    /// The sample times [s].
    pub fn time(&self) -> &[f64] {
        &self.time
    }

    /// The sampled values [N or N m].
    pub fn values(&self) -> &[f64] {
        &self.value
    }

    /// u(t), linear between samples.
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let i = self.time.partition_point(|&ti| ti <= t);
        match (i.checked_sub(1), self.time.get(i)) {
            (None, _) => self.value[0],
            (Some(j), None) => self.value[j],
            (Some(j), Some(&t1)) => {
                let t0 = self.time[j];
                let w = (t - t0) / (t1 - t0);
                self.value[j] + w * (self.value[j + 1] - self.value[j])
            }
        }
    }

    /// The first sample time (a knot, where u's slope changes) later than `after` by more
    /// than `gap`, if any: an integrator steps from knot to knot, since a step across one
    /// sees a kink that its error estimate cannot resolve.
    pub fn next_knot(&self, after: f64, gap: f64) -> Option<f64> {
        let i = self.time.partition_point(|&ti| ti <= after + gap);
        self.time.get(i).copied()
    }

    /// u's slope du/dt over the stretch a step from `after` covers: the stretch between
    /// consecutive samples just after `after`, where a sample closer than `gap` after it
    /// is passed over as [`Input::next_knot`] passes it (a step from `after` stops at the
    /// sample after it, not there). 0 before the first sample and from the last on, where u
    /// is held.
    pub fn slope_after(&self, after: f64, gap: f64) -> f64 {
        self.slope_of_stretch_ending_at(self.time.partition_point(|&ti| ti <= after + gap))
    }

    /// du/dt on the stretch that reaches `t` from the left (from the last sample before `t`
    /// to the first at or after it): the rate at which u arrives at `t`, where a stick's
    /// band is left. 0 at or before the first sample and beyond the last, where u is held.
    pub fn slope_arriving_at(&self, t: f64) -> f64 {
        self.slope_of_stretch_ending_at(self.time.partition_point(|&ti| ti < t))
    }

    /// The slope between samples i - 1 and i; 0 where one of them does not exist.
    fn slope_of_stretch_ending_at(&self, i: usize) -> f64 {
        match (i.checked_sub(1), self.time.get(i)) {
            (Some(j), Some(&t1)) => (self.value[i] - self.value[j]) / (t1 - self.time[j]),
            _ => 0.0,
        }
    }

    /// The first time in (`from`, `until`] at which |u(t) - `centre`| exceeds `half_width`,
    /// exact for the piecewise-linear input: the stick of an axis held by static friction
    /// `half_width` against the restoring force `centre` ends there. `None` when it holds
    /// to `until`.
    pub fn first_exceedance(
        &self,
        from: f64,
        until: f64,
        centre: f64,
        half_width: f64,
    ) -> Option<f64> {
        let excess = |u: f64| (u - centre).abs() - half_width;
        // The breakpoints after `from`, then `until`: u is linear between consecutive ones.
        let start = self.time.partition_point(|&ti| ti <= from);
        let knots = self.time[start..]
            .iter()
            .copied()
            .take_while(|&t| t < until)
            .chain(std::iter::once(until));
        let (mut t0, mut u0) = (from, self.at(from));
        for t1 in knots {
            let u1 = self.at(t1);
            if excess(u1) > 0.0 {
                return Some(crossing(t0, u0, t1, u1, centre, half_width));
            }
            (t0, u0) = (t1, u1);
        }
        None
    }
}

/// Where the line from (t0, u0), inside the band |u - centre| <= half_width, to (t1, u1),
/// outside it, leaves the band.
fn crossing(t0: f64, u0: f64, t1: f64, u1: f64, centre: f64, half_width: f64) -> f64 {
    let edge = centre + half_width * (u1 - centre).signum();
    let du = u1 - u0;
    if du == 0.0 {
        return t1;
    }
    let w = ((edge - u0) / du).clamp(0.0, 1.0);
    t0 + w * (t1 - t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Input {
        Input::new(vec![0.0, 1.0, 2.0, 3.0], vec![0.0, 2.0, 2.0, -4.0]).expect("a valid input")
    }

    #[test]
    fn values_are_linear_between_samples_and_held_beyond() {
        let u = ramp();
        assert_eq!(u.at(-1.0), 0.0);
        assert_eq!(u.at(0.5), 1.0);
        assert_eq!(u.at(1.5), 2.0);
        assert_eq!(u.at(2.5), -1.0);
        assert_eq!(u.at(9.0), -4.0);
    }

    #[test]
    fn the_band_is_left_where_the_line_crosses_its_edge() {
        let u = ramp();
        // |u - 0.5| > 1 first at u = 1.5, t = 0.75.
        assert_eq!(u.first_exceedance(0.0, 3.0, 0.5, 1.0), Some(0.75));
        // Starting on the plateau (on the band's upper edge, u = 2): the fall leaves it at
        // u = -1, half-way down to -4.
        assert_eq!(u.first_exceedance(1.2, 3.0, 0.5, 1.5), Some(2.5));
        assert_eq!(u.first_exceedance(0.0, 2.0, 1.0, 5.0), None);
    }

    #[test]
    fn the_next_knot_lies_beyond_the_gap() {
        let u = ramp();
        assert_eq!(u.next_knot(0.0, 0.0), Some(1.0));
        assert_eq!(u.next_knot(0.5, 0.0), Some(1.0));
        assert_eq!(u.next_knot(1.0 - 1e-12, 1e-9), Some(2.0));
        assert_eq!(u.next_knot(3.0, 0.0), None);
    }

    #[test]
    fn the_slope_is_that_of_the_stretch_ahead() {
        let u = ramp();
        assert_eq!(u.slope_after(-1.0, 0.0), 0.0);
        assert_eq!(u.slope_after(0.0, 0.0), 2.0);
        assert_eq!(u.slope_after(0.5, 0.0), 2.0);
        // At a sample, the stretch that starts there; just short of one by less than the
        // gap, the stretch after it (where a step from there goes).
        assert_eq!(u.slope_after(1.0, 0.0), 0.0);
        assert_eq!(u.slope_after(2.0 - 1e-12, 1e-9), -6.0);
        assert_eq!(u.slope_after(3.0, 0.0), 0.0);
    }

    #[test]
    fn the_slope_arriving_at_a_time_is_that_of_the_piece_ending_there() {
        let u = ramp();
        assert_eq!(u.slope_arriving_at(0.5), 2.0);
        // At a knot: the piece that ends there, not the one that leaves it.
        assert_eq!(u.slope_arriving_at(1.0), 2.0);
        assert_eq!(u.slope_arriving_at(2.0), 0.0);
        assert_eq!(u.slope_arriving_at(2.5), -6.0);
        assert_eq!(u.slope_arriving_at(0.0), 0.0);
        assert_eq!(u.slope_arriving_at(4.0), 0.0);
    }

    #[test]
    fn malformed_inputs_are_refused() {
        assert!(Input::new(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
        assert!(Input::new(vec![0.0], vec![]).is_err());
        assert!(Input::new(vec![0.0, 1.0], vec![1.0, f64::NAN]).is_err());
    }
}
