//! The integration tests of the engine, one module per subject, built into one binary (one
//! link instead of one per file); `util` holds the synthetic records they share.
//! Two files stand apart: `memory.rs`, whose counting global allocator would count every
//! other test running beside it, and `test_laws.rs`, whose modules register friction laws of
//! their own that would join this binary's "every registered model" tests.

mod asymmetric_levels;
mod beyond_speed;
mod calibration;
mod channels;
mod channels_in_motion;
mod compare_verdict;
mod down_weighted;
mod driven_axis;
mod dynamic;
mod false_alarms;
mod false_alarms_driven;
mod false_alarms_rigs;
mod findings_judgement;
mod force_domain;
mod force_jacobian;
mod held_out_states;
mod identify;
mod inverse_dynamics;
mod levels_as_forces;
mod long_decay;
mod nesting;
mod pendulum;
mod plan;
mod polynomial_spring;
mod records;
mod replay;
mod replay_path;
mod robot_joint;
mod robust_targets;
mod simulate;
mod slow_runs;
mod standard_errors;
mod torsion_decay;
mod units;
mod util;
