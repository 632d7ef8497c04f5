//! The values a law's conditions take along a record ([`frictionid_models::Condition`]): the
//! displacement, the acceleration, the input force and the record's named channels, sample
//! by sample.
//!
//! A [`ConditionSource`] holds every column a law could ask for along one record, prepared
//! once (a fit prepares each record once, whatever law it evaluates); [`ConditionSource::bind`]
//! picks the columns of one law's conditions, in the law's order, or names the record and
//! the channel the record lacks.

use super::{Channel, Record};
use crate::error::EngineError;
use frictionid_models::Condition;
use std::collections::BTreeMap;
use std::sync::Arc;

/// The columns a law's conditions may read along one record.
#[derive(Debug, Clone, Default)]
pub struct ConditionSource {
    /// The record's name, for messages.
    record: String,
    /// The displacement at every sample (measured or integrated).
    displacement: Option<Arc<Vec<f64>>>,
    /// The acceleration at every sample (measured or differentiated).
    acceleration: Option<Arc<Vec<f64>>>,
    /// The input force at every sample, where the record has one.
    input: Option<Arc<Vec<f64>>>,
    /// The record's named channels.
    named: BTreeMap<String, Arc<Vec<f64>>>,
}

impl ConditionSource {
    /// The columns of `record`, with its motion's `displacement` and `acceleration` (each one
    /// value per sample, measured or derived by the caller's rule).
    pub fn of_record(record: &Record, displacement: Vec<f64>, acceleration: Vec<f64>) -> Self {
        Self {
            record: record.name.clone(),
            displacement: Some(Arc::new(displacement)),
            acceleration: Some(Arc::new(acceleration)),
            input: record
                .channel(Channel::InputForce)
                .map(|u| Arc::new(u.to_vec())),
            named: record
                .named_channels()
                .into_iter()
                .filter_map(|n| Some((n.to_string(), record.named_channel_shared(n)?)))
                .collect(),
        }
    }

    /// The columns of `wanted` (a law's conditions, in its order); a condition the record
    /// cannot give is an error naming the record and the condition.
    pub fn bind(&self, wanted: &[Condition]) -> Result<ConditionColumns<'_>, EngineError> {
        let columns = wanted
            .iter()
            .map(|c| self.column(c).ok_or_else(|| self.missing(c)))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ConditionColumns { columns })
    }

    fn column(&self, condition: &Condition) -> Option<&[f64]> {
        let column = match condition {
            Condition::Displacement => self.displacement.as_ref(),
            Condition::Acceleration => self.acceleration.as_ref(),
            Condition::InputForce => self.input.as_ref(),
            Condition::Channel(name) => self.named.get(name),
        };
        column.map(|c| c.as_slice())
    }

    fn missing(&self, condition: &Condition) -> EngineError {
        let reason = match condition {
            Condition::Channel(name) => {
                let named: Vec<&str> = self.named.keys().map(String::as_str).collect();
                missing_channel_reason(name, &named)
            }
            Condition::InputForce => "the law reads the input force `u`, which the record does \
                                      not have; name its column with `input_force_column`"
                .to_string(),
            other => format!("the law reads `{other}`, which this record cannot give"),
        };
        EngineError::Record {
            record: self.record.clone(),
            reason,
        }
    }
}

/// Why a law cannot read channel `name` from a record whose named channels are `named`.
pub(crate) fn missing_channel_reason(name: &str, named: &[&str]) -> String {
    format!(
        "the law reads channel `{name}`, which the record does not have (its named channels: \
         {}); name its column in the record's `channels`",
        if named.is_empty() {
            "none".to_string()
        } else {
            named.join(", ")
        }
    )
}

/// The columns of one law's conditions along a record, in the law's order.
#[derive(Debug, Clone, Default)]
pub struct ConditionColumns<'a> {
    columns: Vec<&'a [f64]>,
}

impl ConditionColumns<'_> {
    /// No conditions: a law that reads none.
    pub fn none() -> Self {
        Self::default()
    }

    /// How many conditions.
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// The conditions' values at sample `i` into `out` (one per condition; NaN past a
    /// column's end).
    pub fn fill(&self, i: usize, out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(&self.columns) {
            *o = c.get(i).copied().unwrap_or(f64::NAN);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::TimeBase;

    #[test]
    fn a_law_s_conditions_are_bound_in_its_order_or_named_when_missing() {
        let record = Record::from_time_base("r", TimeBase::new(vec![0.0, 1.0]).unwrap())
            .with_channel(Channel::Velocity, vec![1.0, 1.0])
            .with_named_channel("load", vec![5.0, 6.0]);
        let source = ConditionSource::of_record(&record, vec![0.0, 1.0], vec![0.0, 0.0]);
        let bound = source
            .bind(&[Condition::Channel("load".into()), Condition::Displacement])
            .unwrap();
        let mut at = [0.0; 2];
        bound.fill(1, &mut at);
        assert_eq!(at, [6.0, 1.0]);
        let e = source
            .bind(&[Condition::Channel("temperature".into())])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "record `r`: the law reads channel `temperature`, which the record does not have \
             (its named channels: load); name its column in the record's `channels`"
        );
        let e = source
            .bind(&[Condition::InputForce])
            .unwrap_err()
            .to_string();
        assert!(e.contains("input force `u`"), "{e}");
    }
}
