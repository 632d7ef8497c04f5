//! The TOML configuration file of `simulate`, `fit`, `compare` and `energy`.
//!
//! ```toml
//! [oscillator]                  # m x'' + c x' + k x + F = 0
//! mass = 10.391                 # kg
//! damping = 0.275               # N s/m
//! stiffness = 1982.0            # N/m
//! normal_force = 14.5           # N
//!
//! [model]                       # a registered friction model and its parameter values
//! type = "coulomb"
//! mu = 0.2
//!
//! [fit]                         # optional
//! free = ["mu"]                 # default: every parameter of the model
//! bounds = { mu = [0.0, 1.0] }  # default: the model's physical bounds
//!
//! [simulation]                  # for `simulate`
//! x0 = 0.014                    # m
//! duration = 2.0                # s
//! sample_rate = 1000.0          # Hz
//! noise = 2e-4                  # m/s, optional: also write record.csv with Gaussian noise
//! seed = 1
//!
//! [energy]                      # optional options of the energy analysis
//! method = "savitzky_golay"
//!
//! [record_defaults]             # optional: any [[records]] key, for every record
//! velocity_scale = 1e-3         # (a record's own key wins)
//!
//! [[records]]                   # for fit, compare and energy
//! file = "x14mm.csv"            # relative to this file
//! x0 = 0.014                    # m
//! release = "auto"              # optional: drop the pre-trigger rest (or a time in s)
//! ```
//!
//! Unknown keys are errors that name the key, the line and the nearest valid name; TOML
//! syntax errors name the line and column.

use crate::error::CliError;
use frictionid_engine::data::MAX_SAMPLES;
use frictionid_engine::record::RecordSource;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{build_toml, FrictionModel};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most `[[records]]` entries accepted in one configuration file.
pub const MAX_RECORDS: usize = 1000;

/// Largest configuration file read \[bytes\] (1 MiB).
pub const MAX_CONFIG_BYTES: u64 = 1024 * 1024;

/// A loaded and checked configuration file.
#[derive(Debug, Clone)]
pub struct Config {
    /// The configuration file.
    pub path: PathBuf,
    /// The directory that relative paths in the file are taken from.
    pub base_dir: PathBuf,
    /// The oscillator (`[oscillator]`).
    pub oscillator: Oscillator,
    /// The friction model of `[model]`, if the file has one.
    pub model: Option<ModelConfig>,
    /// Fit options (`[fit]`; defaults when absent).
    pub fit: FitConfig,
    /// Simulation settings (`[simulation]`), if present.
    pub simulation: Option<SimulationConfig>,
    /// Energy-analysis options (`[energy]`; defaults when absent).
    pub energy: EnergyConfig,
    /// The measured records (`[[records]]`), not yet read.
    pub records: Vec<RecordConfig>,
}

/// The `[model]` table: the built model, its validation warnings and the table as written.
#[derive(Debug, Clone)]
pub struct ModelConfig {
    /// The model with the given parameter values (defaults for the others).
    pub model: Box<dyn FrictionModel>,
    /// Admissible but unusual values (printed to stderr by the CLI).
    pub warnings: Vec<String>,
    /// The table as written (`type` and the parameters given explicitly).
    pub table: toml::Table,
}

/// The `[fit]` table.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitConfig {
    /// Names of the parameters to fit; `None` means every parameter of the model that is not
    /// fixed by default.
    pub free: Option<Vec<String>>,
    /// Search bounds [lower, upper] per parameter (default: the model's physical bounds).
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// Largest number of solver iterations.
    pub max_iterations: Option<u64>,
    /// Convergence tolerance of the solver (relative change of the cost).
    pub tolerance: Option<f64>,
    /// Further identifier options, passed through as written (`[fit.options]`).
    pub options: toml::Table,
}

impl FitConfig {
    /// Checks that `free` and `bounds` name parameters of `model` and that each bound is an
    /// ordered, finite-or-infinite pair. The error names the key and suggests the nearest name.
    pub fn check_against(&self, model: &dyn FrictionModel) -> Result<(), CliError> {
        let names: Vec<String> = model.param_info().into_iter().map(|p| p.name).collect();
        let check = |key: &str, what: &str| -> Result<(), CliError> {
            if names.iter().any(|n| n == key) {
                return Ok(());
            }
            Err(CliError::Config(format!(
                "[fit] {what}: model `{}` has no parameter `{key}`{}; its parameters: {}",
                model.name(),
                hint(key, names.iter().map(String::as_str)),
                names.join(", ")
            )))
        };
        for name in self.free.iter().flatten() {
            check(name, "free")?;
        }
        for (name, [lo, hi]) in &self.bounds {
            check(name, "bounds")?;
            if lo.is_nan() || hi.is_nan() || lo >= hi {
                return Err(CliError::Config(format!(
                    "[fit] bounds: `{name}` = [{lo}, {hi}] is not an interval with lower < upper"
                )));
            }
        }
        Ok(())
    }

    /// The free parameter names for `model`: `free` as written, or else every parameter not
    /// marked fixed by default (such as the Stribeck shape exponent).
    pub fn free_names(&self, model: &dyn FrictionModel) -> Vec<String> {
        match &self.free {
            Some(list) => list.clone(),
            None => model
                .param_info()
                .into_iter()
                .filter(|p| !p.fixed_by_default)
                .map(|p| p.name)
                .collect(),
        }
    }
}

/// The ODE integrator chosen in `[simulation.integrator]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorMethod {
    /// Adaptive Dormand-Prince 5(4) with dense output and event location.
    #[default]
    Dopri5,
    /// Closed form for laws affine in v, Dopri5 otherwise.
    Auto,
    /// The exact closed-form propagator (coulomb, viscous_coulomb, none).
    Exact,
    /// Fixed-step explicit Euler (for comparison only).
    Euler,
}

/// `[simulation.integrator]`: integrator choice and tolerances (engine defaults when absent).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IntegratorConfig {
    /// The integration method.
    pub method: IntegratorMethod,
    /// Euler only: steps per natural period.
    pub steps_per_period: Option<f64>,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Largest number of steps.
    pub max_steps: Option<u64>,
    /// Largest number of events (turning points, sticks).
    pub max_events: Option<usize>,
}

/// `[simulation]`: the release state, the time grid and optional synthetic noise.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationConfig {
    /// Release displacement \[m\].
    pub x0: f64,
    /// Release velocity [m/s].
    pub v0: f64,
    /// Initial internal states of the model (default: the model's own).
    pub z0: Option<Vec<f64>>,
    /// Simulated time \[s\].
    pub duration: f64,
    /// Output sample rate \[Hz\].
    pub sample_rate: f64,
    /// Standard deviation of the Gaussian velocity noise of `record.csv` [m/s]; `None`: no record.
    pub noise: Option<f64>,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Integrator options.
    pub integrator: IntegratorConfig,
}

/// The differentiator of the energy analysis (`[energy] method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DifferentiatorMethod {
    /// The paper's differentiation (central differences and a moving average).
    Paper,
    /// Savitzky-Golay smoothing differentiator.
    SavitzkyGolay,
}

/// `[energy]`: energy-analysis options; `None` fields take the engine's defaults.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnergyConfig {
    /// Differentiator.
    pub method: Option<DifferentiatorMethod>,
    /// Savitzky-Golay window length (odd number of samples).
    pub window: Option<usize>,
    /// Savitzky-Golay polynomial order.
    pub order: Option<usize>,
    /// Speeds below this are masked in the friction-force estimate [m/s].
    pub velocity_threshold: Option<f64>,
    /// Reference friction force for the comparison \[N\] (default: from `[model]`).
    pub reference_force: Option<f64>,
}

/// One `[[records]]` entry, checked and resolved (the engine's shared record source).
pub use frictionid_engine::record::source::ResolvedSource as RecordConfig;

// ---------------------------------------------------------------------------------------------
// Raw (as written) structures.

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    oscillator: Option<Oscillator>,
    model: Option<toml::Table>,
    fit: Option<FitConfig>,
    simulation: Option<RawSimulation>,
    energy: Option<EnergyConfig>,
    record_defaults: Option<RecordSource>,
    #[serde(default)]
    records: Vec<RecordSource>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    x0: Option<f64>,
    #[serde(default)]
    v0: f64,
    z0: Option<Vec<f64>>,
    duration: Option<f64>,
    sample_rate: Option<f64>,
    noise: Option<f64>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    integrator: IntegratorConfig,
}

use frictionid_models::suggest::did_you_mean as hint;

/// 1-based line and column of byte offset `pos` in `text`.
fn line_col(text: &str, pos: usize) -> (usize, usize) {
    let before = text.get(..pos.min(text.len())).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

/// The `[section]` header in force at byte offset `pos`, for messages; `None` at the top level.
/// A key inside a table header (`[simulation.integratr]`) belongs to the parent table.
fn section_at(text: &str, pos: usize) -> Option<String> {
    let before = text.get(..pos.min(text.len())).unwrap_or(text);
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    let current = text.get(line_start..).unwrap_or_default();
    let current = current.lines().next().unwrap_or_default().trim();
    if current.starts_with('[') {
        let name = current
            .trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or_default();
        return name
            .rsplit_once('.')
            .map(|(parent, _)| format!("[{}]", parent.trim()));
    }
    text.get(..line_start)
        .unwrap_or_default()
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.split('#').next().unwrap_or(l).trim().to_string())
}

/// Turns a TOML/serde error into one line: `file:line:col: message`, with unknown keys
/// named and the nearest valid key suggested.
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> CliError {
    let raw = e.message().replace('\n', " ");
    let message = if let Some(rest) = raw.strip_prefix("unknown field `") {
        let key = rest.split('`').next().unwrap_or_default();
        let expected: Vec<&str> = rest
            .split("expected")
            .nth(1)
            .map(|s| s.split('`').skip(1).step_by(2).collect())
            .unwrap_or_default();
        let section = e
            .span()
            .and_then(|s| section_at(text, s.start))
            .map(|s| format!(" in {s}"))
            .unwrap_or_else(|| " at the top level".into());
        format!(
            "unknown key `{key}`{section}{}; valid keys: {}",
            hint(key, expected.iter().copied()),
            expected.join(", ")
        )
    } else if let Some(rest) = raw.strip_prefix("missing field `") {
        let key = rest.split('`').next().unwrap_or_default();
        format!("missing key `{key}`")
    } else {
        raw.trim().to_string()
    };
    match e.span() {
        Some(span) => {
            let (line, col) = line_col(text, span.start);
            CliError::Config(format!("{}:{line}:{col}: {message}", path.display()))
        }
        None => CliError::Config(format!("{}: {message}", path.display())),
    }
}

impl Config {
    /// Reads and checks the configuration file at `path`.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        use std::io::Read;
        let io = |e: std::io::Error| {
            CliError::Config(format!(
                "{}: cannot read the config file: {}",
                path.display(),
                match e.kind() {
                    std::io::ErrorKind::NotFound => "no such file".to_string(),
                    std::io::ErrorKind::InvalidData => "it is not UTF-8 text".to_string(),
                    _ => e.to_string(),
                }
            ))
        };
        // Never read past the limit (also for pipes and devices, whose length is unknown).
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .map_err(io)?
            .take(MAX_CONFIG_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        if bytes.len() as u64 > MAX_CONFIG_BYTES {
            return Err(CliError::Config(format!(
                "{}: the config file is over {} KiB; is it the right file?",
                path.display(),
                MAX_CONFIG_BYTES / 1024
            )));
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| io(std::io::Error::from(std::io::ErrorKind::InvalidData)))?;
        Self::parse(path, &text)
    }

    /// Parses configuration `text` as if read from `path` (paths are relative to its directory).
    pub fn parse(path: &Path, text: &str) -> Result<Self, CliError> {
        let raw: RawConfig = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        let file = path.display().to_string();
        let cfg_err = |msg: String| CliError::Config(format!("{file}: {msg}"));
        let base_dir = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));

        let oscillator = raw.oscillator.ok_or_else(|| {
            cfg_err("missing table [oscillator] (mass, damping, stiffness, normal_force)".into())
        })?;
        oscillator
            .validate()
            .map_err(|e| cfg_err(format!("[oscillator]: {e}")))?;

        let model = match raw.model {
            None => None,
            Some(table) => {
                let built = build_toml(&toml::Value::Table(table.clone()))
                    .map_err(|e| cfg_err(format!("[model]: {e}")))?;
                Some(ModelConfig {
                    model: built.model,
                    warnings: built.warnings,
                    table,
                })
            }
        };

        let fit = raw.fit.unwrap_or_default();
        if let Some(m) = &model {
            fit.check_against(m.model.as_ref())
                .map_err(|e| cfg_err(e.to_string()))?;
        }

        let simulation = raw
            .simulation
            .map(|s| simulation_config(s).map_err(cfg_err))
            .transpose()?;

        let energy = raw.energy.unwrap_or_default();

        if raw.records.len() > MAX_RECORDS {
            return Err(cfg_err(format!(
                "{} [[records]] entries; at most {MAX_RECORDS} are accepted",
                raw.records.len()
            )));
        }
        let record_defaults = raw.record_defaults.unwrap_or_default();
        let records = raw
            .records
            .into_iter()
            .enumerate()
            .map(|(i, r)| {
                r.with_defaults(&record_defaults)
                    .resolve(i + 1, &base_dir)
                    .map_err(|e| cfg_err(e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;

        Ok(Self {
            path: path.to_path_buf(),
            base_dir,
            oscillator,
            model,
            fit,
            simulation,
            energy,
            records,
        })
    }

    /// The `[model]`, or an error naming what needs it.
    pub fn require_model(&self, purpose: &str) -> Result<&ModelConfig, CliError> {
        self.model.as_ref().ok_or_else(|| {
            CliError::Config(format!(
                "{}: {purpose} needs a [model] table (e.g. type = \"coulomb\")",
                self.path.display()
            ))
        })
    }

    /// The `[simulation]`, or an error naming what needs it.
    pub fn require_simulation(&self, purpose: &str) -> Result<&SimulationConfig, CliError> {
        self.simulation.as_ref().ok_or_else(|| {
            CliError::Config(format!(
                "{}: {purpose} needs a [simulation] table (x0, duration, sample_rate)",
                self.path.display()
            ))
        })
    }

    /// Reads every `[[records]]` file; an error if there are none.
    pub fn load_records(&self, purpose: &str) -> Result<Vec<Record>, CliError> {
        if self.records.is_empty() {
            return Err(CliError::Config(format!(
                "{}: {purpose} needs at least one [[records]] entry (file, x0)",
                self.path.display()
            )));
        }
        self.records
            .iter()
            .map(|r| r.load_checked(&self.oscillator).map_err(CliError::from))
            .collect()
    }
}

fn positive(what: &str, value: f64) -> Result<f64, String> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(format!("{what} must be a positive number, got {value}"))
    }
}

fn finite(what: &str, value: f64) -> Result<f64, String> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{what} must be finite, got {value}"))
    }
}

fn simulation_config(s: RawSimulation) -> Result<SimulationConfig, String> {
    let x0 =
        s.x0.ok_or("[simulation]: missing `x0` (the release displacement, m)")?;
    let duration = s
        .duration
        .ok_or("[simulation]: missing `duration` (the simulated time, s)")?;
    let noise = match s.noise {
        Some(n) if !(n.is_finite() && n >= 0.0) => {
            return Err(format!("[simulation]: `noise` must be >= 0, got {n}"))
        }
        other => other,
    };
    let duration = positive("[simulation]: `duration`", duration)?;
    let sample_rate = positive(
        "[simulation]: `sample_rate`",
        s.sample_rate.unwrap_or(1000.0),
    )?;
    // The output holds duration * sample_rate + 1 samples: bound it before allocating.
    let samples = duration * sample_rate;
    if samples >= MAX_SAMPLES as f64 {
        return Err(format!(
            "[simulation]: duration * sample_rate = {samples:e} samples; at most {MAX_SAMPLES} are written"
        ));
    }
    Ok(SimulationConfig {
        x0: finite("[simulation]: `x0`", x0)?,
        v0: finite("[simulation]: `v0`", s.v0)?,
        z0: s.z0,
        duration,
        sample_rate,
        noise,
        seed: s.seed,
        integrator: s.integrator,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const OSC: &str =
        "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n";

    fn parse(extra: &str) -> Result<Config, CliError> {
        Config::parse(Path::new("dir/c.toml"), &format!("{OSC}{extra}"))
    }

    #[test]
    fn full_config_parses_with_relative_paths() {
        let c = parse(
            "[model]\ntype = \"coulomb\"\nmu = 0.3\n[fit]\nfree = [\"mu\"]\nbounds = { mu = [0.0, 1.0] }\n\
             [simulation]\nx0 = 0.01\nduration = 1.0\nnoise = 2e-4\nseed = 3\n[simulation.integrator]\nmethod = \"euler\"\n\
             [[records]]\nfile = \"a.csv\"\nx0 = 0.014\nvelocity_scale = 1e-3\n",
        )
        .unwrap();
        assert_eq!(c.oscillator, Oscillator::fmm());
        let m = c.model.unwrap();
        assert_eq!(m.model.params(), vec![0.3]);
        assert_eq!(c.fit.free, Some(vec!["mu".to_string()]));
        let s = c.simulation.unwrap();
        assert_eq!(
            (s.x0, s.sample_rate, s.noise, s.seed),
            (0.01, 1000.0, Some(2e-4), 3)
        );
        assert_eq!(s.integrator.method, IntegratorMethod::Euler);
        assert_eq!(c.records[0].file, Path::new("dir/a.csv"));
        assert_eq!(
            c.records[0]
                .read
                .scale(frictionid_engine::record::Channel::Velocity),
            1e-3
        );
    }

    #[test]
    fn unknown_key_names_line_section_and_suggestion() {
        let e = parse("[simulation]\nx0 = 0.01\ndurtion = 1.0\n").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with(
                "dir/c.toml:8:1: unknown key `durtion` in [simulation] (did you mean `duration`?)"
            ),
            "{msg}"
        );
        let e = parse("[simulaton]\nx0 = 1\n").unwrap_err().to_string();
        assert!(
            e.contains("unknown key `simulaton` at the top level (did you mean `simulation`?)"),
            "{e}"
        );
        let e = parse("[[records]]\nfile = \"a.csv\"\nx0 = 0.01\nvelocity_colum = \"v\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("in [[records]] (did you mean `velocity_column`?)"),
            "{e}"
        );
        let e = parse("[simulation]\nx0 = 0.01\nduration = 1.0\n[simulation.integratr]\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`integratr` in [simulation] (did you mean `integrator`?)"),
            "{e}"
        );
    }

    #[test]
    fn syntax_error_has_line_and_column() {
        let e = parse("[model]\ntype = \"coulomb\nmu = 0.2\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("dir/c.toml:7:"), "{e}");
        assert!(!e.contains('\n'));
    }

    #[test]
    fn missing_pieces_are_named() {
        let e = parse("[[records]]\nfile = \"a.csv\"\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "dir/c.toml: [[records]] entry 1 (`a.csv`): missing `x0` (the release displacement, m)"
        );
        let e = parse("[simulation]\nduration = 1.0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("[simulation]: missing `x0`"), "{e}");
        let e = Config::parse(Path::new("c.toml"), "[model]\ntype = \"coulomb\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing table [oscillator]"), "{e}");
    }

    #[test]
    fn model_and_fit_errors_suggest_names() {
        let e = parse("[model]\ntype = \"colomb\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("[model]: unknown friction model `colomb` (did you mean `coulomb`?)"),
            "{e}"
        );
        let e = parse("[model]\ntype = \"coulomb\"\n[fit]\nfree = [\"mu_\"]\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no parameter `mu_` (did you mean `mu`?)"), "{e}");
        let e = parse("[model]\ntype = \"coulomb\"\n[fit]\nbounds = { mu = [1.0, 0.5] }\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not an interval"), "{e}");
    }

    #[test]
    fn invalid_values_are_rejected() {
        let e = parse("[simulation]\nx0 = 0.01\nduration = -1.0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`duration` must be a positive number"), "{e}");
        let e = Config::parse(
            Path::new("c.toml"),
            "[oscillator]\nmass = 0.0\ndamping = 0.0\nstiffness = 1.0\nnormal_force = 1.0\n",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("[oscillator]: invalid oscillator: `mass` must be > 0"),
            "{e}"
        );
    }
}
