//! A switch for timing a change to the tracer inside one process (docs/tracer-performance.md,
//! "How it is measured").
//!
//! The shared machines this project is measured on drift in speed from process to process
//! and over seconds (the same render 0.15–0.25 s in successive processes), so two builds
//! timed in alternating processes need many rounds for an interval of a few per cent. With
//! both forms of a change in one binary, behind [`on`], `trace --ab-switch` renders the
//! scene repeatedly in one process with the switch off (A) and on (B) in turn, and
//! `scripts/ab-inprocess.sh` pairs renders a fraction of a second apart.
//!
//! Nothing in the tracer reads the switch: a developer puts the change being timed behind
//! `if ab_switch::on()` — read once per call, outside lane loops, so that both forms still
//! vectorise — and takes the switch out again before committing the change. A binary holding
//! both forms lays out its code differently from either alone, so the change's two builds are
//! compared too (`scripts/count-instructions.sh`, and `scripts/ab-trace.sh` where the effect
//! is large enough for it to resolve).

use std::sync::atomic::{AtomicBool, Ordering};

static ON: AtomicBool = AtomicBool::new(false);

/// Whether the switch is on (form B of the change being timed).
#[inline(always)]
pub fn on() -> bool {
    ON.load(Ordering::Relaxed)
}

/// Sets the switch (between renders: a render reads it as it runs).
pub fn set(on: bool) {
    ON.store(on, Ordering::Relaxed);
}
