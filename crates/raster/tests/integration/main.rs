//! The crate's integration tests, one binary (one link) for all of them; each module is
//! one concern.

mod against_truth;
mod device_limits;
mod display_tone_map;
mod exact_at_every_depth;
mod gltf_corpus;
mod memory;
mod methods;
mod mirrored_lights_closed_form;
mod obj_corpus;
mod scene_fuzz;
mod structure;
mod view_rebuild;
