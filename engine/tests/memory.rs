//! The memory a fit holds grows with its records by a bounded number of bytes per sample: a
//! counting global allocator tracks the peak of the bytes allocated while a fit runs on a
//! long record, over what was allocated before it (the record itself).
//!
//! The bound is per sample of the record: a velocity-domain Coulomb fit (the simulation
//! route) holds at most [`VELOCITY_BYTES_PER_SAMPLE`] bytes per sample over the record's own
//! channels (240 before its energy analysis was kept lean and taken by its last reader, the
//! runs' linearisations moved instead of copied, the records' samples shared by their
//! clones); a force-domain fit of Dahl's law along a damper's stroke at most
//! [`FORCE_BYTES_PER_SAMPLE`] (720 while its state cache kept 64 replays). The tests run one
//! after the other (one lock), as the allocator's counters are shared by the whole test
//! binary.

mod util;

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, FitResult};

use frictionid_engine::synthetic::add_gaussian_noise;
use frictionid_engine::testing::DamperStroke;
use frictionid_engine::{EngineError, Oscillator, Record};
use frictionid_models::{Coulomb, Dahl};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Bytes per sample a velocity fit may hold over its record.
const VELOCITY_BYTES_PER_SAMPLE: usize = 100;
/// Bytes per sample a force-domain fit of a dynamic law may hold over its record: the
/// prepared track (motion and target), the few kept replays, the search's Jacobian and
/// residuals and a difference column's replay in flight.
const FORCE_BYTES_PER_SAMPLE: usize = 250;

/// The system allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// One measurement at a time: the counters are the whole binary's.
static SERIAL: Mutex<()> = Mutex::new(());

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

fn grew(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The peak of the bytes allocated while `run` runs, over those live before it.
fn peak_over_baseline<T>(run: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = run();
    let peak = PEAK.load(Ordering::Relaxed);
    (out, peak.saturating_sub(base))
}

/// A free vibration of the FMM stage with Coulomb friction (mu 0.24) released from 140 mm
/// (twenty cycles, nine seconds), `samples` samples at 10 kHz (the exact piecewise
/// solution), with 2e-4 m/s noise.
fn long_coulomb_record(samples: usize) -> Record {
    let osc = Oscillator::fmm();
    let time: Vec<f64> = (0..samples).map(|i| i as f64 * 1e-4).collect();
    let exact = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.14, &time)
        .expect("the exact Coulomb solution");
    let mut v = exact.v;
    add_gaussian_noise(&mut v, 2e-4, 5);
    Record::new("long", time, v, 0.14)
}

/// The memory a fit of `samples` samples may hold at its peak over the baseline.
struct Budget {
    /// The fit, as the failure names it.
    what: &'static str,
    samples: usize,
    bytes_per_sample: usize,
}

impl Budget {
    /// Runs `run` under the allocation counter, checks that its peak keeps to the budget, and
    /// returns its fit.
    fn fit(&self, run: impl FnOnce() -> Result<FitResult, EngineError>) -> FitResult {
        let (result, peak) = peak_over_baseline(run);
        let result = result.expect("the fit");
        let (what, samples, budget) = (self.what, self.samples, self.bytes_per_sample);
        let per_sample = peak / samples;
        assert!(
            per_sample <= budget,
            "{what} of {samples} samples held {peak} bytes at its peak: {per_sample} per sample \
             (at most {budget})"
        );
        result
    }
}

#[test]
fn a_velocity_fit_holds_a_bounded_number_of_bytes_per_sample() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let samples = 200_000;
    let record = [long_coulomb_record(samples)];
    let opts = FitOptions::default();
    let osc = Oscillator::fmm();
    let budget = Budget {
        what: "a velocity fit",
        samples,
        bytes_per_sample: VELOCITY_BYTES_PER_SAMPLE,
    };
    let result = budget.fit(|| fit(&osc, &Coulomb::default(), &record, &opts));
    // The fit itself is right: mu within 1 % of the truth.
    let mu = result.fitted_model.params()[0];
    assert!((mu / 0.24 - 1.0).abs() < 0.01, "mu = {mu}");
}

/// A friction damper's stroke: 2 mm at 3 Hz, `samples` at 1 kHz, Dahl's force (alpha 1,
/// sigma0 5e5 N/m, level 60 N) in closed form along it, 0.5 N noise on the force.
fn damper_stroke(samples: usize) -> Record {
    DamperStroke {
        amplitude: 0.002,
        frequency: 3.0,
        sigma0: 5e5,
        level: 60.0,
        noise: 0.5,
        seed: 11,
    }
    .record(samples)
}

#[test]
fn a_force_domain_fit_holds_a_bounded_number_of_bytes_per_sample() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let samples = 20_000;
    let record = [damper_stroke(samples)];
    // No oscillator given: the levels are forces in N.
    let (osc, mut opts) = util::no_oscillator_force_options();
    opts.params.free = util::free(&["sigma0", "mu_c"]);
    // One thread: the starts in flight at once would depend on the machine's cores.
    let opts = util::serial(opts);
    let budget = Budget {
        what: "a force-domain fit",
        samples,
        bytes_per_sample: FORCE_BYTES_PER_SAMPLE,
    };
    let result = budget.fit(|| fit(&osc, &Dahl::default(), &record, &opts));
    let level = result.fitted_model.params()[1];
    assert!((level / 60.0 - 1.0).abs() < 0.01, "level = {level}");
}
