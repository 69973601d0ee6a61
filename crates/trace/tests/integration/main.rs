//! The crate's integration tests, one binary (one link) for all of them; each module is
//! one concern.

mod analytic;
mod lighting;
mod packets;
mod path;
mod reflection_paths;
mod symmetry_truth;
mod uneven;
