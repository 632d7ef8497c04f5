//! The TOML configuration file of `simulate`, `fit`, `compare` and `energy`.
//!
//! ```toml
//! [oscillator]                  # m x'' + c x' + k x + F = 0
//! mass = 10.391                 # kg
//! damping = 0.275               # N s/m
//! stiffness = 1982.0            # N/m
//! normal_force = 14.5           # N
//! mass_std = 0.0049             # optional: one standard deviation of mass, damping,
//! stiffness_std = 1.3           # stiffness or normal_force (the uncertainty budget)
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
//! [campaign]                    # for campaign (see docs/config.md)
//! manifest = "runs.csv"         # one row per record; group_by, models optional
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
use frictionid_engine::campaign::CampaignSpec;
use frictionid_engine::data::{DataError, RecordSource, RecordUse};
use frictionid_engine::spec::{
    EnergySpec, FitSpec, ModelSpec, OscillatorSpec, PlanSpec, SimulationSpec, Spec, SpecError,
};
use frictionid_engine::Record;
use frictionid_models::build_toml;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Most `[[records]]` entries accepted in one configuration file.
pub const MAX_RECORDS: usize = 1000;

/// Largest configuration file read \[bytes\] (1 MiB).
pub const MAX_CONFIG_BYTES: u64 = 1024 * 1024;

/// A loaded and checked configuration file: the engine's [`Spec`] and the records to read.
#[derive(Debug, Clone)]
pub struct Config {
    /// The configuration file.
    pub path: PathBuf,
    /// The directory that relative paths in the file are taken from.
    pub base_dir: PathBuf,
    /// Oscillator, model, fit, simulation and energy settings.
    pub spec: Spec,
    /// The measured records (`[[records]]`), not yet read.
    pub records: Vec<RecordConfig>,
    /// `[record_defaults]`: keys every record takes unless it gives its own (also a
    /// campaign manifest's rows).
    pub record_defaults: RecordSource,
    /// The `[campaign]` table, if given.
    pub campaign: Option<CampaignSpec>,
    /// The `[plan]` table, if given.
    pub plan: Option<PlanSpec>,
}

/// One `[[records]]` entry, checked and resolved (the engine's shared record source).
pub use frictionid_engine::data::source::ResolvedSource as RecordConfig;

// ---------------------------------------------------------------------------------------------
// Raw (as written) structures.

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    oscillator: Option<OscillatorSpec>,
    model: Option<toml::Table>,
    fit: Option<FitSpec>,
    simulation: Option<SimulationSpec>,
    energy: Option<EnergySpec>,
    record_defaults: Option<RecordSource>,
    #[serde(default)]
    records: Vec<RecordSource>,
    campaign: Option<CampaignSpec>,
    plan: Option<PlanSpec>,
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

/// The names between backticks after "expected" in a serde message.
fn expected_names(rest: &str) -> Vec<&str> {
    rest.split("expected")
        .nth(1)
        .map(|s| s.split('`').skip(1).step_by(2).collect())
        .unwrap_or_default()
}

/// "unknown key `k` in [section] (did you mean `x`?); valid keys: ..." for serde's
/// "unknown field" message (`rest` follows its opening backtick).
fn unknown_key_message(rest: &str, section: Option<String>) -> String {
    let key = rest.split('`').next().unwrap_or_default();
    let expected = expected_names(rest);
    let section = section
        .map(|s| format!(" in {s}"))
        .unwrap_or_else(|| " at the top level".into());
    format!(
        "unknown key `{key}`{section}{}; valid keys: {}",
        hint(key, expected.iter().copied()),
        expected.join(", ")
    )
}

/// "unknown value `v` (did you mean `x`?); valid values: ..." for serde's "unknown variant"
/// message (`rest` follows its opening backtick).
fn unknown_value_message(rest: &str, section: Option<String>) -> String {
    let value = rest.split('`').next().unwrap_or_default();
    let expected = expected_names(rest);
    let section = section.map(|s| format!(" in {s}")).unwrap_or_default();
    format!(
        "unknown value `{value}`{section}{}; valid values: {}",
        hint(value, expected.iter().copied()),
        expected.join(", ")
    )
}

/// Turns a TOML/serde error into one line: `file:line:col: message`, with unknown keys
/// named and the nearest valid key suggested.
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> CliError {
    let raw = e.message().replace('\n', " ");
    let section = || e.span().and_then(|s| section_at(text, s.start));
    let message = if let Some(rest) = raw.strip_prefix("unknown field `") {
        unknown_key_message(rest, section())
    } else if let Some(rest) = raw.strip_prefix("unknown variant `") {
        unknown_value_message(rest, section())
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

/// Reads at most [`MAX_CONFIG_BYTES`] of UTF-8 text from `path` (also for pipes and devices,
/// whose length is unknown).
fn read_config_text(path: &Path) -> Result<String, CliError> {
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
    String::from_utf8(bytes).map_err(|_| io(std::io::Error::from(std::io::ErrorKind::InvalidData)))
}

/// The `[model]` table built into a model spec.
fn model_spec(table: toml::Table) -> Result<ModelSpec, String> {
    let built =
        build_toml(&toml::Value::Table(table.clone())).map_err(|e| format!("[model]: {e}"))?;
    Ok(ModelSpec::new(
        built.model,
        built.warnings,
        table.into_iter().map(|(k, _)| k),
    ))
}

impl Config {
    /// Reads and checks the configuration file at `path`.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let text = read_config_text(path)?;
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
        let model = raw.model.map(model_spec).transpose().map_err(cfg_err)?;
        let spec = Spec::new(
            oscillator,
            model,
            raw.fit.unwrap_or_default(),
            raw.simulation,
            raw.energy.unwrap_or_default(),
        )
        .map_err(|e| cfg_err(e.to_string()))?;
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
                    .resolve_for(i + 1, &base_dir, spec.record_use())
                    .map_err(|e| cfg_err(e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            path: path.to_path_buf(),
            base_dir,
            spec,
            records,
            record_defaults,
            campaign: raw.campaign,
            plan: raw.plan,
        })
    }

    /// A spec error as a config error naming this file.
    pub fn error(&self, e: impl std::fmt::Display) -> CliError {
        CliError::Config(format!("{}: {e}", self.path.display()))
    }

    /// The `[model]`, or an error naming what needs it.
    pub fn require_model(&self, purpose: &str) -> Result<&ModelSpec, CliError> {
        self.spec.require_model(purpose).map_err(|e| self.error(e))
    }

    /// The `[simulation]`, or an error naming what needs it.
    pub fn require_simulation(&self, purpose: &str) -> Result<&SimulationSpec, CliError> {
        self.spec
            .require_simulation(purpose)
            .map_err(|e: SpecError| self.error(e))
    }

    /// Reads the file `[simulation] input` names (as a `[[records]]` entry is read, relative
    /// to the config), if it names one.
    pub fn load_simulation_input(&self) -> Result<Option<Record>, CliError> {
        let Some(source) = self.spec.simulation.as_ref().and_then(|s| s.input.as_ref()) else {
            return Ok(None);
        };
        if source.file.is_none() {
            return Err(self.error("[simulation]: input: missing `file` (the input's data file)"));
        }
        source
            .resolve_for(1, &self.base_dir, RecordUse::Replayed)
            .map_err(|e| self.error(format!("[simulation]: input: {e}")))?
            .load()
            .map(Some)
            .map_err(CliError::from)
    }

    /// Reads every `[[records]]` file; an error if there are none.
    pub fn load_records(&self, purpose: &str) -> Result<Vec<Record>, CliError> {
        if self.records.is_empty() {
            return Err(self.error(format!(
                "{purpose} needs at least one [[records]] entry (file, x0)"
            )));
        }
        self.records
            .iter()
            .map(|r| {
                let record = r
                    .load()
                    .and_then(|record| {
                        self.spec.check_units(&record)?;
                        Ok(record)
                    })
                    .map_err(|e| match e {
                        // An entry's own error names the entry: the file is the config.
                        DataError::Source(entry) => self.error(entry),
                        other => CliError::from(other),
                    })?;
                self.spec.check_law_on(&record).map_err(|e| self.error(e))?;
                Ok(record)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frictionid_engine::identify::PropertyUncertainty;
    use frictionid_engine::Oscillator;

    const OSC: &str =
        "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n";

    fn parse(extra: &str) -> Result<Config, CliError> {
        Config::parse(Path::new("dir/c.toml"), &format!("{OSC}{extra}"))
    }

    /// The error line of the FMM oscillator followed by `extra` (as dir/c.toml).
    fn parse_error(extra: &str) -> String {
        parse(extra).unwrap_err().to_string()
    }

    /// The error line of `text` alone, as c.toml.
    fn bare_parse_error(text: &str) -> String {
        Config::parse(Path::new("c.toml"), text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn full_config_parses_with_relative_paths() {
        let c = parse(
            "[model]\ntype = \"coulomb\"\nmu = 0.3\n[fit]\nfree = [\"mu\"]\nbounds = { mu = [0.0, 1.0] }\n\
             [simulation]\nx0 = 0.01\nduration = 1.0\nnoise = 2e-4\nseed = 3\n[simulation.integrator]\nmethod = \"euler\"\n\
             [[records]]\nfile = \"a.csv\"\nx0 = 0.014\nvelocity_scale = 1e-3\n",
        )
        .unwrap();
        assert_eq!(c.spec.oscillator, Oscillator::fmm());
        let m = c.spec.model.unwrap();
        assert_eq!(m.model.params(), vec![0.3]);
        assert_eq!(c.spec.fit.params.free, Some(vec!["mu".to_string()]));
        let s = c.spec.simulation.unwrap();
        assert_eq!(
            (s.x0, s.sample_rate, s.noise, s.seed),
            (0.01, 1000.0, Some(2e-4), 3)
        );
        assert_eq!(
            s.integrator.method,
            frictionid_engine::spec::IntegratorMethod::Euler
        );
        assert_eq!(c.records[0].file, Path::new("dir/a.csv"));
        assert_eq!(
            c.records[0]
                .read
                .scale(frictionid_engine::record::Channel::Velocity),
            1e-3
        );
    }

    #[test]
    fn unknown_keys_and_names_are_located_and_suggest_the_nearest() {
        let e = parse("[simulation]\nx0 = 0.01\ndurtion = 1.0\n").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with(
                "dir/c.toml:8:1: unknown key `durtion` in [simulation] (did you mean `duration`?)"
            ),
            "{msg}"
        );
        for (config, says) in [
            (
                "[simulaton]\nx0 = 1\n",
                "unknown key `simulaton` at the top level (did you mean `simulation`?)",
            ),
            (
                "[[records]]\nfile = \"a.csv\"\nx0 = 0.01\nvelocity_colum = \"v\"\n",
                "in [[records]] (did you mean `velocity_column`?)",
            ),
            (
                "[simulation]\nx0 = 0.01\nduration = 1.0\n[simulation.integratr]\n",
                "`integratr` in [simulation] (did you mean `integrator`?)",
            ),
            (
                "[model]\ntype = \"colomb\"\n",
                "[model]: unknown friction model `colomb` (did you mean `coulomb`?)",
            ),
            (
                "[model]\ntype = \"coulomb\"\n[fit]\nfree = [\"mu_\"]\n",
                "no parameter `mu_` (did you mean `mu`?)",
            ),
            (
                "[model]\ntype = \"coulomb\"\n[fit]\nbounds = { mu = [1.0, 0.5] }\n",
                "not an interval",
            ),
        ] {
            let e = parse_error(config);
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn oscillator_standard_deviations_reach_the_fit_options() {
        let c = Config::parse(
            Path::new("c.toml"),
            &format!("{OSC}mass_std = 0.0049\nstiffness_std = 1.3\nnormal_force_std = 0.145\n"),
        )
        .unwrap();
        let expected = PropertyUncertainty {
            mass: 0.0049,
            damping: 0.0,
            stiffness: 1.3,
            normal_force: 0.145,
        };
        assert_eq!(c.spec.uncertainty, expected);
        assert_eq!(c.spec.oscillator, Oscillator::fmm());
        let hooks = frictionid_engine::spec::Hooks::default();
        assert_eq!(c.spec.fit_options(&[], &hooks).uncertainty, expected);
        // Absent: known exactly, as before.
        let plain = parse("").unwrap();
        assert!(!plain.spec.uncertainty.any());
    }

    #[test]
    fn bad_oscillator_standard_deviations_are_one_line_errors_naming_the_key() {
        for (line, key) in [
            ("mass_std = -0.1", "mass_std"),
            ("damping_std = nan", "damping_std"),
            ("stiffness_std = inf", "stiffness_std"),
            ("normal_force_std = -1e-3", "normal_force_std"),
        ] {
            let e = bare_parse_error(&format!("{OSC}{line}\n"));
            assert!(e.starts_with("c.toml:"), "{e}");
            assert!(
                e.contains(&format!(
                    "[oscillator]: invalid oscillator: `{key}` must be finite and >= 0"
                )),
                "{e}"
            );
            assert!(!e.contains('\n'), "{e}");
        }
        let e = parse_error("mas_std = 0.1\n");
        assert!(
            e.starts_with(
                "dir/c.toml:6:1: unknown key `mas_std` in [oscillator] (did you mean `mass_std`?)"
            ),
            "{e}"
        );
    }

    #[test]
    fn syntax_error_has_line_and_column() {
        let e = parse_error("[model]\ntype = \"coulomb\nmu = 0.2\n");
        assert!(e.starts_with("dir/c.toml:7:"), "{e}");
        assert!(!e.contains('\n'));
    }

    #[test]
    fn missing_pieces_are_named() {
        let e = parse_error("[simulation]\nduration = 1.0\n");
        assert!(e.contains("[simulation]: missing `x0`"), "{e}");
        let e = bare_parse_error("[model]\ntype = \"coulomb\"\n");
        assert!(e.contains("missing table [oscillator]"), "{e}");
    }

    #[test]
    fn invalid_values_are_rejected() {
        let e = parse_error("[simulation]\nx0 = 0.01\nduration = -1.0\n");
        assert!(e.contains("`duration` must be a positive number"), "{e}");
        let e = bare_parse_error(
            "[oscillator]\nmass = 0.0\ndamping = 0.0\nstiffness = 1.0\nnormal_force = 1.0\n",
        );
        assert!(
            e.contains("[oscillator]: invalid oscillator: `mass` must be > 0"),
            "{e}"
        );
    }
}
