//! The profile of the cost along one parameter: stepped outward on each side with the others
//! re-optimised, and where it crosses the rise that excludes a value at 95 %.

use super::pinned::{merged, pinned_fit, pinned_problem, without};
use super::rigid_limit::Limit;
use super::Standing;
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::search::starts::StartRun;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::result::Identifiability;
use argmin::core::Operator;
use nalgebra::DVector;

/// chi²(1 dof, 95 %) / 2 = 3.8415 / 2: the rise of the cost (half the sum of squares), in
/// residual variances, that excludes a parameter value at 95 %.
pub const PROFILE_DELTA: f64 = 1.920_729_410_347_062;

/// Profile steps on each side.
pub const PROFILE_STEPS: usize = 4;

/// Halvings of a first profile step that fails (a simulation too stiff or degenerate).
pub const PROFILE_HALVINGS: usize = 3;

/// Iterations of the re-optimisation of the other parameters at each profile step.
pub const PROFILE_ITERATIONS: u64 = 12;

/// The precision a profile step's re-optimisation needs, as a fraction of the profile's
/// cost rise: it stops when the Gauss-Newton step promises less decrease (a standing turns
/// on the cost against the rise; the solver's own tests ask about a thousandth of it).
pub const PROFILE_RESOLUTION: f64 = 0.05;

/// Iterations of the re-optimisation at each step of the profile of a rigid limit's
/// stiffness: the other parameters move far along it (LuGre's Stribeck levels and bristle
/// damping change by factors between decades of sigma0), and a profile that stops short of
/// their optimum overstates the lower bound.
pub const LIMIT_PROFILE_ITERATIONS: u64 = 40;

/// A step whose cost, with the others where the previous step left them, lies below the best
/// by more than this fraction of the rise is re-optimised even when it is within the rise: the
/// re-optimisation may reach a full rise below, a point the fit restarts from.
const DESCENT_FRACTION: f64 = 0.5;

/// One profile step: the parameter's internal value, its cost, and the whole point (internal
/// coordinates).
struct ProfilePoint {
    u: f64,
    /// The re-optimised cost, or, for a step only `bounded`, the cost as the previous step
    /// left the others (at least the re-optimised one).
    cost: f64,
    at: DVector<f64>,
    /// The others were not re-optimised: the cost lay within the rise as they stood.
    bounded: bool,
}

/// A profile of the cost along one parameter at the best run.
pub(super) struct Profile<'a, R: Residuals> {
    pub(super) reference: &'a FitProblem<R>,
    pub(super) best: &'a StartRun,
    pub(super) opts: &'a FitOptions,
    /// The model's rigid limit when the records do not reject it: the profile of its
    /// stiffness (the lower side) also tries the others mapped from the limit law at each
    /// stiffness (levels and a critically damped contact). A rejected limit leaves the
    /// stiffness an ordinary parameter.
    pub(super) limit: Option<&'a Limit>,
    /// The precision of a step's cost ([`PROFILE_RESOLUTION`] of the rise).
    pub(super) resolution: f64,
}

impl<R: Residuals + 'static> Profile<'_, R> {
    /// Profile points (internal value, cost) on one side (`side` = ±1), stepping outward
    /// until the cost exceeds `limit` (for the rigid limit's stiffness: at two steps in a
    /// row, since a re-optimisation near the limit can end in a poorer local minimum), a
    /// bound is reached or a step fails; a first step that fails is retried at half the
    /// distance (at most [`PROFILE_HALVINGS`] times).
    fn side(&self, j: usize, side: f64, limit: f64) -> Vec<ProfilePoint> {
        let confirmations = if self.limit.is_some_and(|l| l.is_first_stiffness(j)) {
            2
        } else {
            1
        };
        let f = &self.reference.layout[j];
        let (lo, hi) = f.internal_bounds();
        let centre = self.best.u[j];
        let mut step = if f.log {
            std::f64::consts::LN_10
        } else {
            centre.abs().max(1.0)
        };
        let mut others = without(&self.best.u, &[(j, centre)]);
        let mut out: Vec<ProfilePoint> = Vec::new();
        let mut halvings = 0;
        while out.len() < PROFILE_STEPS {
            let previous = out.last().map_or(centre, |p| p.u);
            let u = (previous + side * step).clamp(lo, hi);
            if u == previous {
                break;
            }
            let pins = [(j, u)];
            if let Some(cost) = self.within_as_left(&pins, &others, limit) {
                out.push(ProfilePoint {
                    u,
                    cost,
                    at: merged(&others, &pins, self.best.u.len()),
                    bounded: true,
                });
                continue;
            }
            match self.step_fit(&pins, &others) {
                None if out.is_empty() && halvings < PROFILE_HALVINGS => {
                    step /= 2.0;
                    halvings += 1;
                }
                None => break,
                Some(run) => {
                    if run.cost > limit {
                        self.reoptimise_last(j, &mut out);
                    }
                    others = run.u;
                    out.push(ProfilePoint {
                        u,
                        cost: run.cost,
                        at: merged(&others, &pins, self.best.u.len()),
                        bounded: false,
                    });
                    let above = out.iter().rev().take_while(|p| p.cost > limit).count();
                    if above >= confirmations {
                        break;
                    }
                }
            }
        }
        out
    }

    /// The cost at the step `pins` with the others as the previous step left them
    /// (`others`), when it already lies within `limit` and less than [`DESCENT_FRACTION`] of
    /// the rise below the best. The profile is the least cost over the others, so such a
    /// step lies inside the interval whatever a re-optimisation would find, and one
    /// evaluation replaces it; the step before a crossing is re-optimised later
    /// ([`Self::reoptimise_last`]), where the crossing is interpolated from its cost.
    fn within_as_left(
        &self,
        pins: &[(usize, f64)],
        others: &DVector<f64>,
        limit: f64,
    ) -> Option<f64> {
        let rise = limit - self.best.cost;
        let problem = pinned_problem(self.reference, pins)?;
        let r = problem.apply(others).ok()?;
        let cost = 0.5 * r.norm_squared();
        let within = cost <= limit && cost >= self.best.cost - DESCENT_FRACTION * rise;
        within.then_some(cost)
    }

    /// Re-optimises the last point of `out` when it was only bounded (a profile that rises
    /// past the limit next interpolates its crossing from that point's least cost); a
    /// re-optimisation that fails leaves the bound.
    fn reoptimise_last(&self, j: usize, out: &mut [ProfilePoint]) {
        let Some(last) = out.last_mut().filter(|p| p.bounded) else {
            return;
        };
        let pins = [(j, last.u)];
        if let Some(run) = self.step_fit(&pins, &without(&last.at, &pins)) {
            if run.cost < last.cost {
                last.cost = run.cost;
                last.at = merged(&run.u, &pins, last.at.len());
            }
            last.bounded = false;
        }
    }

    /// The others re-optimised at a profile step `pins` from where the previous step left
    /// them (`previous`); a step of the rigid limit's stiffness also from the others mapped
    /// from the limit law at that stiffness (with more iterations), keeping the lower end: the
    /// cost near a rigid limit has several minima in the levels.
    fn step_fit(&self, pins: &[(usize, f64)], previous: &DVector<f64>) -> Option<StartRun> {
        let &[(j, u)] = pins else {
            return None;
        };
        let Some(limit) = self.limit.filter(|l| l.is_first_stiffness(j)) else {
            return pinned_fit(
                self.reference,
                pins,
                previous,
                self.opts,
                (PROFILE_ITERATIONS, Some(self.resolution)),
            );
        };
        let run = |start: &DVector<f64>| {
            pinned_fit(
                self.reference,
                pins,
                start,
                self.opts,
                (LIMIT_PROFILE_ITERATIONS, Some(self.resolution)),
            )
        };
        let Some(mapped) = limit.target_at_stiffness(self.reference, self.best, (j, u)) else {
            return run(previous);
        };
        let mapped = without(&mapped, pins);
        let (a, b) = if self.opts.hooks.parallel {
            rayon::join(|| run(previous), || run(&mapped))
        } else {
            (run(previous), run(&mapped))
        };
        [a, b]
            .into_iter()
            .flatten()
            .min_by(|x, y| x.cost.total_cmp(&y.cost))
    }

    /// The standing of slot `j` for a cost rise `delta` (absolute), and the lowest profile
    /// point (internal coordinates) when its cost lies more than `delta` below the best.
    /// `open_above`: the cost the parameter's upper side runs to (a rigid limit the records
    /// do not exclude): that side is open and not profiled.
    pub(super) fn standing(
        &self,
        j: usize,
        delta: f64,
        open_above: Option<f64>,
    ) -> (Standing, Option<DVector<f64>>) {
        let best = self.best.cost;
        // The two sides are independent refits: side by side on two threads.
        let (below, above) = if open_above.is_some() {
            (self.side(j, -1.0, best + delta), Vec::new())
        } else if self.opts.hooks.parallel {
            rayon::join(
                || self.side(j, -1.0, best + delta),
                || self.side(j, 1.0, best + delta),
            )
        } else {
            (
                self.side(j, -1.0, best + delta),
                self.side(j, 1.0, best + delta),
            )
        };
        let lowest = below
            .iter()
            .chain(&above)
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .filter(|p| p.cost < best - delta)
            .map(|p| p.at.clone());
        // A profile that found a lower cost (a parameter still running on) measures from it.
        let floor = below
            .iter()
            .chain(&above)
            .map(|p| p.cost)
            .chain(open_above)
            .fold(best, f64::min);
        let pairs = |side: &[ProfilePoint]| -> Vec<(f64, f64)> {
            side.iter().map(|p| (p.u, p.cost)).collect()
        };
        let (below, above) = (pairs(&below), pairs(&above));
        let centre = (self.best.u[j], best);
        let f = &self.reference.layout[j];
        // A side that cannot be evaluated at all (too stiff to simulate) counts as open.
        let rise = Rise { floor, delta };
        let low = outer_crossing(centre, &below, rise).map(|u| f.to_physical(u));
        let high = outer_crossing(centre, &above, rise).map(|u| f.to_physical(u));
        let (class, bound) = match (low, high) {
            (Some(_), Some(_)) => (Identifiability::Determined, None),
            (Some(b), None) => (Identifiability::LowerBound, Some(b)),
            (None, Some(b)) => (Identifiability::UpperBound, Some(b)),
            (None, None) => (Identifiability::NotIdentifiable, None),
        };
        (Standing { class, bound }, lowest)
    }
}

/// The rise of a profile that excludes a value: `delta` above the profile's least cost
/// `floor`.
#[derive(Debug, Clone, Copy)]
struct Rise {
    floor: f64,
    delta: f64,
}

impl Rise {
    /// The cost that excludes a value.
    fn limit(&self) -> f64 {
        self.floor + self.delta
    }

    /// The signed root of a cost's rise above the floor, sqrt(cost - floor): linear in the
    /// parameter on each side of the optimum where the profile is quadratic.
    fn root(&self, cost: f64) -> f64 {
        (cost - self.floor).max(0.0).sqrt()
    }
}

/// Where the profile rises above the limit for good: [`crossing`] from its last point within
/// the limit (a point above it followed by one within is a re-optimisation that stopped in a
/// poorer local minimum, not the edge of the interval).
fn outer_crossing(centre: (f64, f64), points: &[(f64, f64)], rise: Rise) -> Option<f64> {
    match points.iter().rposition(|&(_, c)| c <= rise.limit()) {
        Some(k) => crossing(points[k], &points[k + 1..], rise),
        None => crossing(centre, points, rise),
    }
}

/// Where the profile first rises above the limit, from `centre`: between the last point
/// within it and the first beyond, linear in the root of the rise (exact for a quadratic
/// profile, which a profile is near its optimum). Linear in the cost itself, the crossing
/// lies too close to the point within whenever the profile curves upwards: between the
/// optimum and a step at four times the limit's rise it stood at a quarter of the step,
/// where the rise is a quarter of the limit's, not at half.
fn crossing(centre: (f64, f64), points: &[(f64, f64)], rise: Rise) -> Option<f64> {
    let limit = rise.limit();
    let mut previous = centre;
    for &(u, c) in points {
        if c > limit {
            let (from, to, target) = (rise.root(previous.1), rise.root(c), rise.delta.sqrt());
            let t = if to > from {
                ((target - from) / (to - from)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            return Some(previous.0 + t * (u - previous.0));
        }
        previous = (u, c);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::super::flat::flat_and_delta;
    use super::*;
    use crate::identify::problem::force_along_motion::ForceAlongMotion;
    use crate::identify::search::starts::{run_start, RunSlot};
    use crate::identify::search::strategy::{law_force_problem, offset_stroke};
    use crate::record::{Channel, Record};
    use std::sync::Arc;

    /// Dahl's law along a damper stroke whose force is Dahl's at sigma0 1e13 N/m (rigid even
    /// over the nanometre steps at the reversals: a Coulomb force with 0.2 N of noise), fitted
    /// from there: its stiffness is bounded below only, and the profile upward stays flat.
    fn rigid_dahl_fit() -> (FitProblem<ForceAlongMotion>, StartRun, FitOptions) {
        let (stroke, osc, opts) = offset_stroke(0.0);
        let x = stroke.channel(Channel::Displacement).unwrap().to_vec();
        let force = crate::testing::dahl_force_along(&x, 1e13, 50.0);
        let noisy: Vec<f64> = stroke
            .channel(Channel::Force)
            .unwrap()
            .iter()
            .zip(crate::testing::dahl_force_along(&x, 4e5, 50.0))
            .zip(&force)
            .map(|((measured, clean), rigid)| rigid + (measured - clean))
            .collect();
        let records: Arc<[Record]> = vec![stroke.with_channel(Channel::Force, noisy)].into();
        let truth = frictionid_models::Dahl {
            sigma0: 1e13,
            mu_c: 50.0,
            alpha: 1.0,
        };
        let (reference, start) = law_force_problem(&records, osc, &opts, &truth);
        let (problem, _) = law_force_problem(&records, osc, &opts, &truth);
        let slot = RunSlot {
            start: 0,
            starts: 1,
            max_iterations: 100,
            pace: None,
            cost_resolution: None,
            explain: false,
        };
        let u0 = reference.internal(&start);
        let best = run_start(problem, u0, &opts.search, &opts.hooks, slot).unwrap();
        (reference, best, opts)
    }

    /// A step within the rise as the previous step left the others costs one evaluation
    /// instead of a re-optimisation, and that cost bounds the profile: the others
    /// re-optimised there (the oracle: a pinned fit of its own, to convergence) end no
    /// higher, so the step lies inside the interval either way. The steps downward, where the
    /// cost rises past the limit, are re-optimised, the last one within included, so the
    /// crossing is interpolated from least costs.
    #[test]
    fn a_step_within_the_rise_as_left_is_bounded_by_one_evaluation() {
        let (reference, best, opts) = rigid_dahl_fit();
        let j = 0;
        assert_eq!(reference.layout[j].name, "sigma0");
        let flat = flat_and_delta(&reference, &best).unwrap().unwrap();
        assert!(flat.slots.contains(&j), "{:?}", flat.slots);
        let delta = flat.delta;
        let profile = Profile {
            reference: &reference,
            best: &best,
            opts: &opts,
            limit: None,
            resolution: PROFILE_RESOLUTION * delta,
        };
        let limit = best.cost + delta;
        let upward = profile.side(j, 1.0, limit);
        let bounded: Vec<&ProfilePoint> = upward.iter().filter(|p| p.bounded).collect();
        assert!(!bounded.is_empty(), "no step was bounded");
        for p in bounded {
            assert!(p.cost <= limit, "{} > {limit}", p.cost);
            let pins = [(j, p.u)];
            let full = pinned_fit(
                &reference,
                &pins,
                &without(&best.u, &pins),
                &opts,
                (100, None),
            )
            .expect("a pinned fit");
            assert!(
                full.cost <= p.cost * (1.0 + 1e-12),
                "{} > {}",
                full.cost,
                p.cost
            );
        }
        let downward = profile.side(j, -1.0, limit);
        let crossing = downward.iter().position(|p| p.cost > limit);
        let crossing = crossing.expect("the stiffness is bounded below");
        assert!(downward[..=crossing]
            .iter()
            .rev()
            .take(2)
            .all(|p| !p.bounded));
    }

    /// A rise above a floor of 0 by `delta`.
    fn rise(delta: f64) -> Rise {
        Rise { floor: 0.0, delta }
    }

    #[test]
    fn the_crossing_of_a_quadratic_profile_is_exact_between_its_points() {
        // The profile u^2 (the cost of a linear least-squares parameter, in its standard
        // errors) crosses the rise 1.92 at sqrt(1.92) = 1.386, from its optimum to a step at
        // u = 2 (cost 4) or from a point within (u = 1) to one beyond (u = 3), either side.
        let exact = 1.92_f64.sqrt();
        let u = crossing((0.0, 0.0), &[(2.0, 4.0)], rise(1.92)).unwrap();
        assert!((u - exact).abs() < 1e-12, "{u}");
        let u = crossing((0.0, 0.0), &[(-1.0, 1.0), (-3.0, 9.0)], rise(1.92)).unwrap();
        assert!((u + exact).abs() < 1e-12, "{u}");
        // Above a floor the profile found below the optimum's cost, the same.
        let raised = Rise {
            floor: 10.0,
            delta: 1.92,
        };
        let u = crossing((0.0, 10.0), &[(2.0, 14.0)], raised).unwrap();
        assert!((u - exact).abs() < 1e-12, "{u}");
        assert_eq!(
            crossing((0.0, 0.0), &[(1.0, 0.5), (2.0, 1.0)], rise(1.92)),
            None
        );
    }

    #[test]
    fn the_outer_crossing_skips_a_point_above_the_limit_that_a_later_one_undercuts() {
        // -1 rose to 3 (a poor local minimum), -2 fits again at 1, -3 rises to 4: the
        // interval ends between -2 and -3, where the root of the rise, 1 at -2 and 2 at -3,
        // reaches sqrt(2): at -2 - (sqrt(2) - 1).
        let points = [(-1.0, 3.0), (-2.0, 1.0), (-3.0, 4.0)];
        let u = outer_crossing((0.0, 0.0), &points, rise(2.0)).unwrap();
        assert!((u + 1.0 + 2.0_f64.sqrt()).abs() < 1e-12, "{u}");
        assert_eq!(outer_crossing((0.0, 0.0), &points[..2], rise(2.0)), None);
        assert_eq!(
            outer_crossing((0.0, 0.0), &points[..1], rise(2.0)),
            crossing((0.0, 0.0), &points[..1], rise(2.0))
        );
    }
}
