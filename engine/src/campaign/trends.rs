//! Trends of the fitted parameters against the numeric conditions: a straight line and a
//! power law, each by weighted least squares (weights 1 / standard error², the covariance
//! scaled by the reduced chi², as lmfit does by default), and which of the two fits better.

use super::table::{CampaignRow, RowVerdict};
use serde::{Deserialize, Serialize};

/// The form of a trend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TrendForm {
    /// y = a + b x.
    Linear,
    /// y = a x^b (fitted as ln y = ln a + b ln x; positive values only).
    PowerLaw,
}

/// One fitted trend: y = a + b x (linear) or y = a x^b (power law).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineFit {
    /// Its form.
    pub form: TrendForm,
    /// The intercept (linear) or the prefactor (power law).
    pub a: f64,
    /// Standard error of `a`.
    pub a_std_error: Option<f64>,
    /// The slope (linear) or the exponent (power law).
    pub b: f64,
    /// Standard error of `b`.
    pub b_std_error: Option<f64>,
    /// Weighted sum of squared residuals of the parameter values (the same weights for both
    /// forms, so the sums compare).
    pub weighted_sse: f64,
    /// n ln(weighted_sse / n) + 2 k, k = 2.
    pub aic: f64,
}

impl LineFit {
    /// The trend's value at `x`.
    pub fn at(&self, x: f64) -> f64 {
        match self.form {
            TrendForm::Linear => self.a + self.b * x,
            TrendForm::PowerLaw => self.a * x.powf(self.b),
        }
    }
}

/// The trends of one model's parameter against one numeric condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trend {
    /// The model.
    pub model: String,
    /// The parameter.
    pub parameter: String,
    /// The condition.
    pub condition: String,
    /// Groups used (converged fits with a value and the condition).
    pub points: usize,
    /// Whether every point had a standard error (else the fit is unweighted).
    pub weighted: bool,
    /// The straight line.
    pub linear: Option<LineFit>,
    /// The power law (only when every value and condition is positive).
    pub power_law: Option<LineFit>,
    /// The form with the lower AIC.
    pub better: Option<TrendForm>,
}

/// A point of a trend: condition, value, weight.
type Point = (f64, f64, f64);

/// Every trend of `rows`: for each model, each parameter it fitted and each of `numeric`
/// conditions that takes at least two values among its converged groups, when at least
/// three groups have a value.
pub fn campaign_trends(rows: &[CampaignRow], numeric: &[String]) -> Vec<Trend> {
    let mut trends = Vec::new();
    let mut models: Vec<&str> = Vec::new();
    for r in rows {
        if !models.contains(&r.model.as_str()) {
            models.push(&r.model);
        }
    }
    for model in models {
        let of_model: Vec<&CampaignRow> = rows
            .iter()
            .filter(|r| r.model == model && r.converged && r.verdict != RowVerdict::Failed)
            .collect();
        let mut params: Vec<&str> = Vec::new();
        for p in of_model.iter().flat_map(|r| &r.parameters) {
            if p.status != "fixed" && !params.contains(&p.name.as_str()) {
                params.push(&p.name);
            }
        }
        for param in &params {
            for condition in numeric {
                if let Some(t) = trend(model, param, condition, &of_model) {
                    trends.push(t);
                }
            }
        }
    }
    trends
}

/// The points (condition, value, standard error) of one parameter against one condition.
pub(crate) fn trend_points(
    rows: &[&CampaignRow],
    param: &str,
    condition: &str,
) -> Vec<(f64, f64, Option<f64>)> {
    rows.iter()
        .filter_map(|r| {
            let x = r.condition(condition)?.number()?;
            let p = r.param(param)?;
            Some((x, p.value?, p.std_error.filter(|s| *s > 0.0)))
        })
        .filter(|(x, y, _)| x.is_finite() && y.is_finite())
        .collect()
}

fn trend(model: &str, param: &str, condition: &str, rows: &[&CampaignRow]) -> Option<Trend> {
    let raw = trend_points(rows, param, condition);
    let distinct = {
        let mut xs: Vec<f64> = raw.iter().map(|p| p.0).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        xs.len()
    };
    if raw.len() < 3 || distinct < 2 {
        return None;
    }
    let weighted = raw.iter().all(|p| p.2.is_some());
    let points: Vec<Point> = raw
        .iter()
        .map(|&(x, y, s)| {
            (
                x,
                y,
                if weighted {
                    s.map_or(1.0, |s| 1.0 / (s * s))
                } else {
                    1.0
                },
            )
        })
        .collect();
    let linear = weighted_line(&points)
        .map(|(a, b, sa, sb)| finish(TrendForm::Linear, a, b, sa, sb, &points));
    let power_law = power_law(&points);
    let better = match (&linear, &power_law) {
        (Some(l), Some(p)) => Some(if p.aic < l.aic {
            TrendForm::PowerLaw
        } else {
            TrendForm::Linear
        }),
        (Some(_), None) => Some(TrendForm::Linear),
        (None, Some(_)) => Some(TrendForm::PowerLaw),
        (None, None) => None,
    };
    Some(Trend {
        model: model.into(),
        parameter: param.into(),
        condition: condition.into(),
        points: points.len(),
        weighted,
        linear,
        power_law,
        better,
    })
}

/// The fit of form `form` with its sums of squares over `points` (in the values' own space).
fn finish(
    form: TrendForm,
    a: f64,
    b: f64,
    sa: Option<f64>,
    sb: Option<f64>,
    points: &[Point],
) -> LineFit {
    let mut fit = LineFit {
        form,
        a,
        a_std_error: sa,
        b,
        b_std_error: sb,
        weighted_sse: 0.0,
        aic: f64::NAN,
    };
    let sse: f64 = points
        .iter()
        .map(|&(x, y, w)| w * (y - fit.at(x)).powi(2))
        .sum();
    let n = points.len() as f64;
    fit.weighted_sse = sse;
    fit.aic = n * (sse.max(f64::MIN_POSITIVE) / n).ln() + 4.0;
    fit
}

/// y = a x^b through ln y = ln a + b ln x, weighted by (y / s)² (the standard error of ln y
/// is s / y); `None` unless every x and y is positive.
fn power_law(points: &[Point]) -> Option<LineFit> {
    if points.iter().any(|&(x, y, _)| x <= 0.0 || y <= 0.0) {
        return None;
    }
    let logs: Vec<Point> = points
        .iter()
        .map(|&(x, y, w)| (x.ln(), y.ln(), w * y * y))
        .collect();
    let (ln_a, b, s_ln_a, sb) = weighted_line(&logs)?;
    let a = ln_a.exp();
    Some(finish(
        TrendForm::PowerLaw,
        a,
        b,
        s_ln_a.map(|s| a * s),
        sb,
        points,
    ))
}

/// The weighted least-squares line y = a + b x and the standard errors of a and b (the
/// covariance (X' W X)^-1 scaled by chi² / (n - 2)); `None` when the x do not vary.
pub(crate) fn weighted_line(points: &[Point]) -> Option<(f64, f64, Option<f64>, Option<f64>)> {
    let (mut s, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for &(x, y, w) in points {
        s += w;
        sx += w * x;
        sy += w * y;
    }
    // Centred sums keep the determinant accurate when x is far from 0.
    let (mx, my) = (sx / s, sy / s);
    let cxx: f64 = points.iter().map(|&(x, _, w)| w * (x - mx).powi(2)).sum();
    let cxy: f64 = points
        .iter()
        .map(|&(x, y, w)| w * (x - mx) * (y - my))
        .sum();
    if cxx.is_nan() || cxx <= 0.0 || !cxx.is_finite() {
        return None;
    }
    let b = cxy / cxx;
    let a = my - b * mx;
    let dof = points.len().saturating_sub(2);
    let chi2: f64 = points
        .iter()
        .map(|&(x, y, w)| w * (y - a - b * x).powi(2))
        .sum();
    let scale = (dof > 0).then(|| chi2 / dof as f64);
    let var_b = scale.map(|k| k / cxx);
    let var_a = scale.map(|k| k * (1.0 / s + mx * mx / cxx));
    Some((a, b, var_a.map(f64::sqrt), var_b.map(f64::sqrt)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line through exact points has zero residuals and the slope of the points; with
    /// scatter the standard error of the slope is the textbook sqrt(s² / Sxx).
    #[test]
    fn weighted_line_matches_the_textbook_formulas() {
        let exact: Vec<Point> = (0..5)
            .map(|i| (i as f64, 2.0 - 0.5 * i as f64, 1.0))
            .collect();
        let (a, b, _, sb) = weighted_line(&exact).unwrap();
        assert!((a - 2.0).abs() < 1e-12 && (b + 0.5).abs() < 1e-12);
        assert!(sb.unwrap() < 1e-12);
        let noisy = [
            (0.0, 0.1, 1.0),
            (1.0, 0.9, 1.0),
            (2.0, 2.2, 1.0),
            (3.0, 2.9, 1.0),
        ];
        let (a, b, _, sb) = weighted_line(&noisy).unwrap();
        // x mean 1.5, y mean 1.525: Sxx = 5, Sxy = 2.1375 + 0.3125 + 0.3375 + 2.0625 = 4.85.
        assert!((b - 0.97).abs() < 1e-12, "{b}");
        assert!((a - (1.525 - 0.97 * 1.5)).abs() < 1e-12);
        let sse: f64 = noisy.iter().map(|&(x, y, _)| (y - a - b * x).powi(2)).sum();
        assert!((sb.unwrap() - (sse / 2.0 / 5.0).sqrt()).abs() < 1e-12);
        assert!(weighted_line(&[(1.0, 1.0, 1.0), (1.0, 2.0, 1.0)]).is_none());
    }

    /// Points on y = 3 x^-0.5 are a power law exactly: it wins, with its exponent.
    #[test]
    fn a_power_law_is_recognised() {
        let points: Vec<Point> = (1..6)
            .map(|i| (i as f64, 3.0 / (i as f64).sqrt(), 1.0))
            .collect();
        let p = power_law(&points).unwrap();
        assert!((p.a - 3.0).abs() < 1e-12 && (p.b + 0.5).abs() < 1e-12);
        let (a, b, sa, sb) = weighted_line(&points).unwrap();
        let l = finish(TrendForm::Linear, a, b, sa, sb, &points);
        assert!(p.aic < l.aic);
        assert!(power_law(&[(0.0, 1.0, 1.0), (1.0, 2.0, 1.0), (2.0, 3.0, 1.0)]).is_none());
    }
}
