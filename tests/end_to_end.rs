//! mirrorbox end to end: the CLI as a user runs it. One test binary (one link) for every
//! concern; each module is one of them.

mod common;

mod advise;
mod build_profile;
mod cli;
mod exchange;
mod hardening;
mod memory;
mod mitsuba;
mod readme;
mod reports_html;
mod scripts;
mod slurm;
mod tracer_bench;
mod viewer;
