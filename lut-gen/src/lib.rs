//! lut-gen: everything slotforge knows about a channel mix before any HDL.
//!
//! - [`mix`]: the TOML format and its validation (errors name file, line, field);
//! - [`parts`]: ADC and mux models as data, and the SPI timing they imply;
//! - [`synth`]: slot-grid choice and jitter-free placement, or a diagnosis;
//! - [`validate`]: an independent proof of a schedule's promises;
//! - [`lut`]: the slot LUT as a full frame table and in compact form;
//! - [`ports`]: the pin contract of `slotforge_top` (names, roles, widths, lanes, limits, `ports.json`);
//! - [`hostlink`]: the link to the host planned from the schedule (divider, bytes per frame, FIFO depth, latency, minimum baud);
//! - [`oswords`]: what the OS says about a user's file, in words;
//! - [`fixes`]: changes that make an infeasible mix fit, each tried before it is offered;
//! - [`audit`]: rates, intervals, headroom, settling and Nyquist, as text or JSON.

pub mod fixes;
pub mod hostlink;
pub mod mix;
pub mod oswords;
pub mod parts;
pub mod ports;
pub mod schedule;
pub mod synth;
pub mod validate;

pub use mix::{load, parse, Mix, MixError};
pub use oswords::{io_words, write_words};
pub use schedule::{seconds, FrameGrid, SamplingInstant, Schedule};
pub use synth::{synthesize, synthesize_within, Infeasible, Verdict};
pub mod audit;
pub mod lut;

pub use audit::AuditReport;
