//! The Eq. 7 energy analyses of a fit's records, each computed once: the data-driven guess
//! reads its friction level from the analysis the energy check needs at the end, when nothing
//! that analysis depends on (the oscillator's m, c and k, the release displacement, the
//! velocity offset) was fitted.
//!
//! A kept analysis holds only the series those two read ([`for_the_fit`]): on a long record
//! each series is as large as the record, and the cache holds them through the whole search.

use crate::energy::{analyze_record, EnergyAnalysis, EnergyOptions, MechanicalEnergy};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::Record;
use std::sync::{Arc, Mutex};

/// What an analysis of a record depends on besides its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    index: usize,
    /// The whole oscillator: its inertia, damping and restoring law enter the analysis.
    oscillator: Oscillator,
    x0: f64,
    options: EnergyOptions,
}

/// An energy analysis asked for: the fit's record `index` (`record`, its velocity as
/// measured) under `osc` and `options`.
#[derive(Debug, Clone, Copy)]
pub struct AnalysisRequest<'a> {
    pub index: usize,
    pub record: &'a Record,
    pub osc: &'a Oscillator,
    pub options: &'a EnergyOptions,
}

impl AnalysisRequest<'_> {
    /// The analysis computed afresh ([`analyze_record`]).
    pub fn compute(&self) -> Result<Arc<EnergyAnalysis>, EngineError> {
        Ok(Arc::new(analyze_record(
            self.record,
            self.osc,
            self.options,
        )?))
    }

    fn key(&self) -> Key {
        Key {
            index: self.index,
            oscillator: *self.osc,
            x0: self.record.x0,
            options: *self.options,
        }
    }
}

/// The analyses of the records of one fit, by record index (the fit's records never change
/// their samples; a velocity corrected by a fitted offset is not asked for here).
#[derive(Debug, Default)]
pub struct AnalysisCache(Mutex<Vec<(Key, Arc<EnergyAnalysis>)>>);

impl AnalysisCache {
    /// The energy analysis `request` asks for: kept from an earlier request with the same
    /// record index, oscillator, release displacement and options, else computed.
    pub fn analysis(
        &self,
        request: AnalysisRequest<'_>,
    ) -> Result<Arc<EnergyAnalysis>, EngineError> {
        let key = request.key();
        if let Some(kept) = self.find(&key) {
            return Ok(kept);
        }
        let analysis = Arc::new(for_the_fit(analyze_record(
            request.record,
            request.osc,
            request.options,
        )?));
        if let Ok(mut entries) = self.0.lock() {
            entries.push((key, analysis.clone()));
        }
        Ok(analysis)
    }

    /// The same, for its last reader: a kept analysis leaves the cache (on a long record it
    /// holds several series as long as the record).
    pub fn take(&self, request: AnalysisRequest<'_>) -> Result<Arc<EnergyAnalysis>, EngineError> {
        let key = request.key();
        let kept = self.0.lock().ok().and_then(|mut entries| {
            let at = entries.iter().position(|(k, _)| *k == key)?;
            Some(entries.swap_remove(at).1)
        });
        match kept {
            Some(analysis) => Ok(analysis),
            None => request.compute(),
        }
    }

    fn find(&self, key: &Key) -> Option<Arc<EnergyAnalysis>> {
        let entries = self.0.lock().ok()?;
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, a)| a.clone())
    }
}

/// `analysis` with the series a fit reads (the guess its scalars, the energy check
/// ([`crate::identify::assessment::energy_check`]) time, velocity, Eq. 7's force and the
/// half-cycles; the displacement and potential energy only to weigh a quantised displacement's
/// turning points), the others (acceleration, energy rate, kinetic and total energy) emptied.
fn for_the_fit(analysis: EnergyAnalysis) -> EnergyAnalysis {
    let quantised = analysis.displacement_step.is_some();
    let keep = |series: Vec<f64>| if quantised { series } else { Vec::new() };
    let EnergyAnalysis { x, mechanical, .. } = analysis;
    EnergyAnalysis {
        x: keep(x),
        a: Vec::new(),
        mechanical: MechanicalEnergy {
            kinetic: Vec::new(),
            potential: keep(mechanical.potential),
            energy: Vec::new(),
        },
        de_dt: Vec::new(),
        ..analysis
    }
}

impl Clone for AnalysisCache {
    /// A clone starts empty (it may serve other records).
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PartialEq for AnalysisCache {
    /// A cache never makes two producers differ.
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::release_records;
    use frictionid_models::Coulomb;

    /// The same analysis value (its masked samples are NaN, so compared as written out).
    fn same(a: &EnergyAnalysis, b: &EnergyAnalysis) -> bool {
        serde_json::to_string(a).ok() == serde_json::to_string(b).ok()
    }

    #[test]
    fn an_analysis_is_kept_for_the_same_inputs_only() {
        let osc = Oscillator::fmm();
        let records =
            release_records(&osc, &Coulomb { mu: 0.24 }, &[0.014], 2.0, 1000.0, 2e-4, 3).unwrap();
        let rec = &records[0];
        let options = EnergyOptions::default();
        let cache = AnalysisCache::default();
        let request = |record, osc| AnalysisRequest {
            index: 0,
            record,
            osc,
            options: &options,
        };
        let first = cache.analysis(request(rec, &osc)).unwrap();
        let fresh = |record, osc| for_the_fit(analyze_record(record, osc, &options).unwrap());
        assert!(same(&first, &fresh(rec, &osc)));
        // The series no reader of a fit's analysis reads are not kept.
        assert!(first.a.is_empty() && first.de_dt.is_empty() && first.x.is_empty());
        assert_eq!(first.friction.len(), rec.len());
        let again = cache.analysis(request(rec, &osc)).unwrap();
        assert!(Arc::ptr_eq(&first, &again));
        let heavier = Oscillator {
            mass: osc.mass * 1.01,
            ..osc
        };
        let other = cache.analysis(request(rec, &heavier)).unwrap();
        // Its last reader takes it out: the next request computes it again.
        let taken = cache.take(request(rec, &heavier)).unwrap();
        assert!(Arc::ptr_eq(&other, &taken));
        let again = cache.analysis(request(rec, &heavier)).unwrap();
        assert!(!Arc::ptr_eq(&other, &again));
        assert!(!Arc::ptr_eq(&first, &other));
        assert!(same(&other, &fresh(rec, &heavier)));
        let mut moved = rec.clone();
        moved.x0 += 1e-3;
        let shifted = cache.analysis(request(&moved, &osc)).unwrap();
        assert!(same(&shifted, &fresh(&moved, &osc)));
        assert!(!Arc::ptr_eq(&first, &shifted));
    }
}
