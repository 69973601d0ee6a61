//! The experiment registry's tests, one binary (CONTRIBUTING, "Where tests go").

mod records;
mod registry;
mod resume_keys;
