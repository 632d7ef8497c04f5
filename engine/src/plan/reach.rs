//! What the candidates cannot give: the parameters whose predicted relative standard error
//! stays above the reach, and the smallest change along the candidates' own dimensions (a
//! faster sample rate, a smaller or larger release, another normal force, a longer record, a
//! stronger or weaker excitation) that would bring them within it.

use super::experiment::{Experiment, ExperimentInput};
use serde::Serialize;

/// A dimension of an experiment a change can move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Dimension {
    /// The sample rate.
    SampleRate,
    /// The release displacement.
    Release,
    /// The normal force.
    NormalForce,
    /// The record length.
    Duration,
    /// The multisine's amplitude.
    Amplitude,
}

impl Dimension {
    /// The words for the dimension.
    pub fn words(self) -> &'static str {
        match self {
            Self::SampleRate => "sample rate",
            Self::Release => "release x0",
            Self::NormalForce => "normal force",
            Self::Duration => "record length",
            Self::Amplitude => "multisine amplitude",
        }
    }

    /// The dimension's value in `e` (`normal` the oscillator's normal force); `None` where
    /// the experiment has no such value to change.
    pub fn value(self, e: &Experiment, normal: f64) -> Option<f64> {
        match self {
            Self::SampleRate => Some(e.sample_rate),
            Self::Duration => Some(e.duration),
            Self::Release => (e.x0 != 0.0).then_some(e.x0),
            Self::NormalForce => Some(e.normal_force.unwrap_or(normal)).filter(|n| *n > 0.0),
            Self::Amplitude => match &e.input {
                Some(ExperimentInput::Multisine(m)) => Some(m.amplitude),
                _ => None,
            },
        }
    }

    /// `e` with this dimension scaled by `factor`, if it has it.
    pub fn scaled(self, e: &Experiment, factor: f64, normal: f64) -> Option<Experiment> {
        let value = self.value(e, normal)? * factor;
        let mut out = e.clone();
        match self {
            Self::SampleRate => out.sample_rate = value,
            Self::Duration => out.duration = value,
            Self::Release => out.x0 = value,
            Self::NormalForce => out.normal_force = Some(value),
            Self::Amplitude => {
                if let Some(ExperimentInput::Multisine(m)) = &mut out.input {
                    m.amplitude = value;
                }
            }
        }
        Some(out)
    }
}

/// The changes tried, smallest first (by |ln factor|).
pub const LADDER: [(Dimension, f64); 18] = [
    (Dimension::SampleRate, 2.0),
    (Dimension::Release, 0.5),
    (Dimension::Release, 2.0),
    (Dimension::NormalForce, 0.5),
    (Dimension::NormalForce, 2.0),
    (Dimension::Duration, 2.0),
    (Dimension::Amplitude, 2.0),
    (Dimension::Amplitude, 0.5),
    (Dimension::SampleRate, 4.0),
    (Dimension::Release, 0.25),
    (Dimension::Release, 4.0),
    (Dimension::NormalForce, 0.25),
    (Dimension::NormalForce, 4.0),
    (Dimension::Duration, 4.0),
    (Dimension::Amplitude, 4.0),
    (Dimension::SampleRate, 10.0),
    (Dimension::SampleRate, 20.0),
    (Dimension::SampleRate, 50.0),
];

/// A change that brings a parameter within reach.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Change {
    /// What changes.
    pub dimension: Dimension,
    /// By what factor, on every recommended record.
    pub factor: f64,
    /// The recommended records' values before.
    pub from: Vec<f64>,
    /// And after.
    pub to: Vec<f64>,
    /// The parameter's predicted relative standard error after the change.
    pub relative_std: f64,
}

impl Change {
    /// The change in words: "sample rate 1000 Hz -> 20000 Hz (x20)".
    pub fn words(&self, unit: &str) -> String {
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{}", round_sig(*x)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        format!(
            "{} {} {unit} -> {} {unit} (x{}) on the recommended records",
            self.dimension.words(),
            list(&self.from),
            list(&self.to),
            round_sig(self.factor)
        )
    }
}

/// The unit of a dimension's values.
pub fn unit_of(dimension: Dimension) -> &'static str {
    match dimension {
        Dimension::SampleRate => "Hz",
        Dimension::Release => "m",
        Dimension::NormalForce | Dimension::Amplitude => "N",
        Dimension::Duration => "s",
    }
}

/// A relative value as a percentage to two significant digits (`23 %`, `0.015 %`).
pub fn percent(r: f64) -> String {
    let p = 100.0 * r;
    if !p.is_finite() || p <= 0.0 {
        return format!("{p} %");
    }
    if p >= 10.0 {
        format!("{p:.0} %")
    } else {
        let digits = (1 - p.log10().floor() as i32).clamp(0, 12) as usize;
        format!("{p:.digits$} %")
    }
}

/// `x` to four significant digits.
fn round_sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let digits = 3 - x.abs().log10().floor() as i32;
    let p = 10f64.powi(digits);
    (x * p).round() / p
}

/// A parameter out of reach: its predicted relative standard error with the recommended
/// records (`None`: no information at all), the best any one candidate gives, all
/// candidates together, and the smallest change found that would reach it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutOfReach {
    /// The parameter.
    pub parameter: String,
    /// With the recommended records (and those already taken).
    pub relative_std: Option<f64>,
    /// With all the candidates together.
    pub all_candidates: Option<f64>,
    /// The smallest change among the ladder's that brings it within reach, if any.
    pub change: Option<Change>,
    /// Along each other dimension, the smallest change that brings it within reach (smallest
    /// first): what else would do, for a rig whose first choice cannot change.
    pub alternatives: Vec<Change>,
    /// For a contact stiffness: the records' evidence against the rigid limit, when it is
    /// below the fit's threshold.
    pub rigid_limit: Option<RigidEvidence>,
    /// The finding in words.
    pub message: String,
}

/// The evidence of the recommended records against the rigid limit of the law.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RigidEvidence {
    /// The limit law.
    pub limit: String,
    /// chi^2 of the limit law fitted to the noise-free records.
    pub chi2: f64,
    /// chi^2_95 of the parameters it removes: the fit's test.
    pub threshold: f64,
    /// The chi^2 at which a fit would reject the limit 9 times in 10.
    pub needed: f64,
}

impl OutOfReach {
    /// The smallest changes found, one per dimension, smallest first.
    pub fn changes(&self) -> impl Iterator<Item = &Change> {
        self.change.iter().chain(&self.alternatives)
    }

    /// Whether a change along `dimension` has been found.
    pub fn has_change_along(&self, dimension: Dimension) -> bool {
        self.changes().any(|c| c.dimension == dimension)
    }

    /// Records `change` as the smallest along its dimension (the first found is the smallest
    /// overall).
    pub fn add_change(&mut self, change: Change) {
        if self.has_change_along(change.dimension) {
            return;
        }
        match self.change {
            None => self.change = Some(change),
            Some(_) => self.alternatives.push(change),
        }
    }

    /// The finding in words, for a reach of `reach` (relative); `sought`: whether changes
    /// were looked for.
    pub fn describe(&mut self, reach: f64, sought: bool) {
        let pct = |r: Option<f64>| match r {
            Some(r) => percent(r),
            None => "unbounded (no information)".into(),
        };
        let mut text = format!(
            "`{}` is out of reach of these candidates: predicted relative standard error {} \
             with the recommended records, {} with all of them (the reach is {})",
            self.parameter,
            pct(self.relative_std),
            pct(self.all_candidates),
            percent(reach)
        );
        if let Some(r) = &self.rigid_limit {
            text.push_str(&format!(
                "; the recommended records would not tell it from a rigid contact: `{}` fits \
                 them within chi2 = {:.3}, where a fit's test (at {:.2}) would reject it 9 \
                 times in 10 only from {:.1}, so a fit could bound it only from below",
                r.limit, r.chi2, r.threshold, r.needed
            ));
        }
        match &self.change {
            Some(c) => text.push_str(&format!(
                "; the smallest change that reaches it: {} (predicted {})",
                c.words(unit_of(c.dimension)),
                percent(c.relative_std)
            )),
            None if sought => text.push_str(
                "; none of the changes tried (sample rate up to x50, release and normal force \
                 x0.25 to x4, record length up to x4, amplitude x0.5 to x4) reaches it",
            ),
            None => {}
        }
        if !self.alternatives.is_empty() {
            let others: Vec<String> = self
                .alternatives
                .iter()
                .map(|c| {
                    format!(
                        "{} (predicted {})",
                        c.words(unit_of(c.dimension)),
                        percent(c.relative_std)
                    )
                })
                .collect();
            text.push_str(&format!("; or else {}", others.join("; or ")));
        }
        self.message = text;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ladder_runs_from_small_to_large_changes_and_changes_apply() {
        let size = |f: f64| f.ln().abs();
        assert!(LADDER
            .windows(2)
            .all(|w| size(w[0].1) <= size(w[1].1) + 1e-12));
        let e = Experiment::release(0.01, 2.0, 1000.0);
        let faster = Dimension::SampleRate.scaled(&e, 20.0, 14.5).unwrap();
        assert_eq!(faster.sample_rate, 20_000.0);
        let lighter = Dimension::NormalForce.scaled(&e, 0.5, 14.5).unwrap();
        assert_eq!(lighter.normal_force, Some(7.25));
        assert!(Dimension::Amplitude.scaled(&e, 2.0, 14.5).is_none());
    }

    fn change(dimension: Dimension, factor: f64, from: f64) -> Change {
        Change {
            dimension,
            factor,
            from: vec![from],
            to: vec![from * factor],
            relative_std: 0.2,
        }
    }

    fn unreached() -> OutOfReach {
        OutOfReach {
            parameter: "sigma0".into(),
            relative_std: Some(0.9),
            all_candidates: Some(0.9),
            change: None,
            alternatives: Vec::new(),
            rigid_limit: None,
            message: String::new(),
        }
    }

    /// The first change found is the smallest, one per dimension is kept, and the message
    /// names each: a rig that cannot change its normal force reads the sample rate to take.
    #[test]
    fn the_smallest_change_along_each_dimension_is_named() {
        let mut o = unreached();
        o.add_change(change(Dimension::NormalForce, 2.0, 14.5));
        o.add_change(change(Dimension::NormalForce, 4.0, 14.5));
        o.add_change(change(Dimension::SampleRate, 10.0, 1000.0));
        assert_eq!(o.change.as_ref().map(|c| c.factor), Some(2.0));
        assert_eq!(o.alternatives.len(), 1);
        o.describe(0.5, true);
        assert!(
            o.message.contains("normal force 14.5 N -> 29 N (x2)"),
            "{}",
            o.message
        );
        assert!(
            o.message
                .contains("or else sample rate 1000 Hz -> 10000 Hz (x10)"),
            "{}",
            o.message
        );
    }

    /// Without a search for changes the message does not claim that none reaches it.
    #[test]
    fn no_search_no_claim_about_changes() {
        let mut o = unreached();
        o.describe(0.5, false);
        assert!(!o.message.contains("none of the changes"), "{}", o.message);
        o.describe(0.5, true);
        assert!(
            o.message.contains("none of the changes tried"),
            "{}",
            o.message
        );
    }
}
