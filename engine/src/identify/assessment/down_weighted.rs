//! The samples a robust loss down-weighted at the optimum.
//!
//! Under `loss = "huber"` or `"soft_l1"` each residual r (in units of its record's noise) has
//! the weight rho'((r / C)^2) of iteratively reweighted least squares: 1 within the loss's
//! scale C, less beyond. A fit keeps each record's weights ([`RobustWeights`]) so that plots
//! can mark the samples the loss set aside, and says in a finding how many there were and
//! where.

use crate::identify::values::search::RobustLoss;
use crate::identify::values::{Check, Finding, RobustWeights, Status};

/// Time ranges a finding's message lists at most.
const LISTED_RANGES: usize = 5;

/// The weights `loss` gives the noise-weighted `residuals` of a record's compared samples
/// at `time` (one each); `None` under least squares or when the lengths differ.
pub(crate) fn robust_weights(
    loss: RobustLoss,
    residuals: &[f64],
    time: &[f64],
) -> Option<RobustWeights> {
    if loss.is_linear() || residuals.len() != time.len() {
        return None;
    }
    let weights: Vec<f64> = residuals.iter().map(|&r| loss.weight(r)).collect();
    let down: Vec<usize> = (0..weights.len())
        .filter(|&i| weights[i] < RobustWeights::DOWN_WEIGHTED)
        .collect();
    Some(RobustWeights {
        loss: loss.loss,
        count: down.len(),
        of: weights.len(),
        least: weights.iter().copied().fold(1.0, f64::min),
        ranges: runs(&down).map(|(a, b)| [time[a], time[b]]).collect(),
        times: down.iter().map(|&i| time[i]).collect(),
        weights,
    })
}

/// The contiguous runs of the ascending indices `ix`, as (first, last).
fn runs(ix: &[usize]) -> impl Iterator<Item = (usize, usize)> + '_ {
    let starts = (0..ix.len()).filter(move |&k| k == 0 || ix[k] != ix[k - 1] + 1);
    starts.map(move |k| {
        let end = (k..ix.len())
            .take_while(|&j| j == k || ix[j] == ix[j - 1] + 1)
            .last()
            .unwrap_or(k);
        (ix[k], ix[end])
    })
}

/// The finding of the samples of `record` the loss down-weighted (`None` when none were): a
/// pass stating how many, the least weight and where.
pub(crate) fn down_weighted_finding(record: &str, w: &RobustWeights) -> Option<Finding> {
    if w.count == 0 {
        return None;
    }
    let share = w.count as f64 / w.of.max(1) as f64;
    let listed: Vec<String> = w
        .ranges
        .iter()
        .take(LISTED_RANGES)
        .map(|[a, b]| format!("{a:.4}-{b:.4} s"))
        .collect();
    let more = match w.ranges.len().saturating_sub(LISTED_RANGES) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    Some(Finding::new(
        Check::DownWeighted,
        Status::Pass,
        Some(100.0 * share),
        format!(
            "record `{record}`: the {} loss gave {} of {} compared samples ({:.2} %) a \
             weight below {} (least {:.3}): residuals beyond about twice its scale, in {} ranges: {}{more}",
            w.loss.name(),
            w.count,
            w.of,
            100.0 * share,
            RobustWeights::DOWN_WEIGHTED,
            w.least,
            w.ranges.len(),
            listed.join(", "),
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::values::search::Loss;

    fn huber() -> RobustLoss {
        RobustLoss {
            loss: Loss::Huber,
            scale: 1.345,
        }
    }

    #[test]
    fn huber_down_weights_only_residuals_beyond_twice_its_scale() {
        let time = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];
        let r = [0.5, -1.3, 2.6, 3.0, -20.0, 1.0];
        let w = robust_weights(huber(), &r, &time).expect("weights");
        assert_eq!(w.weights[0], 1.0);
        assert_eq!(w.weights[1], 1.0);
        // 2.6 < 2 C = 2.69: down, but not below a half.
        assert!(w.weights[2] > 0.5 && w.weights[2] < 1.0);
        assert!((w.weights[4] - 1.345 / 20.0).abs() < 1e-12);
        assert_eq!((w.count, w.of), (2, 6));
        assert_eq!(w.ranges, vec![[0.3, 0.4]]);
        assert_eq!(w.times, vec![0.3, 0.4]);
        let f = down_weighted_finding("r", &w).expect("a finding");
        assert!(f.message.contains("2 of 6"), "{}", f.message);
        assert!(f.message.contains("huber"), "{}", f.message);
    }

    #[test]
    fn least_squares_keeps_no_weights_and_a_clean_record_no_finding() {
        assert!(robust_weights(RobustLoss::linear(), &[30.0], &[0.0]).is_none());
        let w = robust_weights(huber(), &[0.1, -0.2], &[0.0, 1.0]).expect("weights");
        assert!(down_weighted_finding("r", &w).is_none());
    }

    #[test]
    fn runs_split_at_gaps() {
        let r: Vec<_> = runs(&[1, 2, 3, 7, 9, 10]).collect();
        assert_eq!(r, vec![(1, 3), (7, 7), (9, 10)]);
    }
}
