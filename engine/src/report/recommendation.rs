//! The one voice of compare's verdict: the law to use, then why, read from the comparison's
//! verdict and scores: its held-out validation, its parsimony among the laws that validate as
//! well, what the records determine of it (and which laws were set aside), its own fit's
//! checks, and the information criteria as information.

use super::fit::verdict_line;
use super::format::{fmt_criterion, fmt_num};
use super::Status;
use crate::identify::compare::verdict::within_noise;
use crate::identify::{
    Comparison, ComparisonVerdict, FitResult, FittedParam, Identifiability, LawValidation,
};

/// The law to use and why: `headline` names it (or says none can be recommended), each of
/// `reasons` is one ground it rests on, `status` is the recommended fit's own (its checks
/// decide the colour of a verdict box, never another law's).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Recommendation {
    /// The recommended fit's status (`Fail` when no law can be recommended).
    pub status: Status,
    /// The law to use (`` `coulomb` ``), or why none can be; writers put it after
    /// "Recommended:".
    pub headline: String,
    /// The grounds, one sentence each, the held-out validation first.
    pub reasons: Vec<String>,
    /// The law recommended, if any.
    pub law: Option<String>,
}

/// The recommendation of `c` (`None` when no model could be fitted).
pub(crate) fn recommendation(c: &Comparison) -> Option<Recommendation> {
    let verdict = c.verdict.as_ref()?;
    let Some(fit) = recommended_fit(c) else {
        return Some(nothing_to_recommend(c, verdict));
    };
    let (status, fit_text) = verdict_line(fit);
    let mut reasons = vec![
        validation_reason(c, verdict, fit),
        parsimony_reason(c, fit),
        identifiability_reason(verdict, fit),
        format!("its own fit: {fit_text}"),
    ];
    reasons.extend(caveat(verdict));
    reasons.extend(information_reason(c, fit));
    Some(Recommendation {
        status,
        headline: format!("`{}`", fit.model),
        reasons,
        law: Some(fit.model.clone()),
    })
}

/// The fit the verdict recommends.
pub(crate) fn recommended_fit(c: &Comparison) -> Option<&FitResult> {
    let name = c.verdict.as_ref()?.recommended.as_deref()?;
    c.ranking.iter().find(|f| f.model == name)
}

/// Every law set aside, and why.
fn nothing_to_recommend(c: &Comparison, verdict: &ComparisonVerdict) -> Recommendation {
    let mut reasons: Vec<String> = verdict
        .set_aside
        .iter()
        .map(|s| format!("`{}` is set aside: {}", s.model, s.reason))
        .collect();
    reasons.extend(c.ranking.first().map(|best| {
        format!(
            "information criteria (information only): the lowest AIC is `{}`'s",
            best.model
        )
    }));
    Recommendation {
        status: Status::Fail,
        headline: "none, every fitted law is set aside".into(),
        reasons,
        law: None,
    }
}

/// The held-out score of `model`, when it has one.
fn score<'a>(c: &'a Comparison, model: &str) -> Option<&'a LawValidation> {
    c.validation
        .iter()
        .find(|v| v.model == model && v.validation_rms.is_some())
}

/// `1.980e-4 m/s (folds' spread 2.593e-6)`.
fn score_text(v: &LawValidation, unit: &str) -> String {
    let rms = fmt_num(v.validation_rms.unwrap_or(f64::NAN));
    match v.validation_rms_spread {
        Some(s) => format!("{rms} {unit} (folds' spread {})", fmt_num(s)),
        None => format!("{rms} {unit}"),
    }
}

/// How the law's held-out error compares with the lowest.
fn validation_reason(c: &Comparison, verdict: &ComparisonVerdict, fit: &FitResult) -> String {
    let (Some(scheme), Some(own)) = (c.validation_scheme, score(c, &fit.model)) else {
        return "held-out validation: none (the records were too short to hold data out), so \
                the law was chosen by AIC"
            .into();
    };
    let unit = &fit.residual_unit;
    let head = format!("held-out validation ({})", scheme.describe());
    let top = verdict
        .best_validated
        .as_deref()
        .and_then(|name| score(c, name));
    match top {
        Some(top) if top.model != fit.model => {
            let relation = if within_noise(own, top) {
                "within the folds' noise of the lowest"
            } else {
                "above the lowest"
            };
            let aside = verdict
                .set_aside
                .iter()
                .find(|s| s.model == top.model)
                .map(|s| format!(", set aside: {}", s.reason))
                .unwrap_or_default();
            format!(
                "{head}: rms {}, {relation} (`{}`, {} {unit}{aside})",
                score_text(own, unit),
                top.model,
                fmt_num(top.validation_rms.unwrap_or(f64::NAN)),
            )
        }
        _ => format!("{head}: the lowest held-out rms, {}", score_text(own, unit)),
    }
}

/// The laws whose held-out error is within the folds' noise of the lowest, `fit` aside.
fn others_within<'a>(c: &'a Comparison, fit: &FitResult) -> Vec<&'a FitResult> {
    let Some(top) = c
        .validation
        .iter()
        .filter(|v| v.validation_rms.is_some())
        .min_by(|a, b| {
            let r = |v: &LawValidation| v.validation_rms.unwrap_or(f64::INFINITY);
            r(a).total_cmp(&r(b))
        })
    else {
        return Vec::new();
    };
    c.ranking
        .iter()
        .filter(|f| f.model != fit.model)
        .filter(|f| score(c, &f.model).is_some_and(|v| within_noise(v, top)))
        .collect()
}

/// The law's free parameters against those of the laws that validate as well.
fn parsimony_reason(c: &Comparison, fit: &FitResult) -> String {
    let n = fit.free_parameters;
    let own = format!("{n} free parameter{}", if n == 1 { "" } else { "s" });
    let mut others = others_within(c, fit);
    if others.is_empty() {
        return format!("parsimony: {own}; no other law validates as well");
    }
    others.sort_by_key(|f| f.free_parameters);
    let listed: Vec<String> = others
        .iter()
        .map(|f| format!("`{}` ({})", f.model, f.free_parameters))
        .collect();
    let fewest = others.iter().all(|f| f.free_parameters >= n);
    let relation = if fewest {
        "the fewest of the laws that validate as well"
    } else {
        "the simplest of them that nothing sets aside"
    };
    format!("parsimony: {own}, {relation}: {}", listed.join(", "))
}

/// What the records determine of the law's free parameters, and the laws set aside.
fn identifiability_reason(verdict: &ComparisonVerdict, fit: &FitResult) -> String {
    let free: Vec<_> = fit.parameters.iter().filter(|p| p.free).collect();
    let determined: Vec<String> = free
        .iter()
        .filter(|p| {
            p.identifiability
                .is_none_or(|i| i == Identifiability::Determined)
        })
        .map(|p| format!("`{}`", p.name))
        .collect();
    let bounded: Vec<String> = free
        .iter()
        .filter(|p| {
            p.identifiability
                .is_some_and(|i| i != Identifiability::Determined)
        })
        .map(|p| one_sided(p))
        .collect();
    let mut text = if bounded.is_empty() {
        format!(
            "identifiability: the records determine every free parameter of `{}` ({})",
            fit.model,
            determined.join(", ")
        )
    } else {
        format!(
            "identifiability: the records determine {} of `{}`; only bounded (95 %): {}",
            if determined.is_empty() {
                "no parameter".to_string()
            } else {
                determined.join(", ")
            },
            fit.model,
            bounded.join(", ")
        )
    };
    let aside: Vec<String> = verdict
        .set_aside
        .iter()
        .map(|s| format!("`{}` ({})", s.model, s.reason))
        .collect();
    if !aside.is_empty() {
        text.push_str(&format!("; set aside: {}", aside.join("; ")));
    }
    text
}

/// A parameter the records do not determine: `sigma0` > 1.302e9 (at 95 %), or `v_s`
/// not identified.
fn one_sided(p: &FittedParam) -> String {
    let bound = p.bound.map(fmt_num).unwrap_or_else(|| "-".into());
    match p.identifiability {
        Some(Identifiability::LowerBound) => format!("`{}` > {bound}", p.name),
        Some(Identifiability::UpperBound) => format!("`{}` < {bound}", p.name),
        _ => format!("`{}` not identified", p.name),
    }
}

/// What the verdict adds after its "but" (friction levels at a bound), when it does.
fn caveat(verdict: &ComparisonVerdict) -> Option<String> {
    verdict
        .message
        .split_once("; but ")
        .map(|(_, rest)| format!("caution: {rest}"))
}

/// Where the law stands by AIC, shown as information.
fn information_reason(c: &Comparison, fit: &FitResult) -> Option<String> {
    let best = c.ranking.first()?;
    Some(if best.model == fit.model {
        format!(
            "information criteria (information only): `{}` has the lowest AIC too",
            fit.model
        )
    } else {
        format!(
            "information criteria (information only): the lowest AIC is `{}`'s, {} below `{}`'s",
            best.model,
            fmt_criterion(fit.aic - best.aic),
            fit.model
        )
    })
}
