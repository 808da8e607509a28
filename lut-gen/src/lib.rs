//! lut-gen: everything slotforge knows about a channel mix before any HDL.
//!
//! - `mix`: the TOML format and its validation (errors name file, line, field);
//! - `parts`: ADC and mux models as data, and the SPI timing they imply;
//! - `command`: the command words sent to converters that take one, and their pipeline;
//! - `synth`: slot-grid choice and jitter-free placement, or a diagnosis;
//! - `validate`: an independent proof of a schedule's promises;
//! - [`lut`]: the slot LUT as a full frame table and in compact form;
//! - `ports`: the pin contract of `slotforge_top` (names, roles, widths, lanes, limits, `ports.json`);
//! - `fpga`: the FPGA parts of the open families (tool and cell-model names);
//! - `hostlink`: the link to the host planned from the schedule (divider, bytes per frame, FIFO depth, latency, minimum baud);
//! - `oswords`: what the OS says about a user's file, in words;
//! - `fixes`: changes that make an infeasible mix fit, each tried before it is offered;
//! - `switching`: when a mode switch takes effect, and the worst reaction to a trigger or the pin;
//! - `audit`: rates, intervals, headroom, settling and Nyquist, as text or JSON.

mod audit;
mod command;
mod fixes;
mod fpga;
mod holdoff;
mod hostlink;
// A public namespace, not an export list: the slot table's three file forms
// (`lut::to_hex`, `lut::to_csv`, `lut::to_markdown`) and its compact form
// read as what they are only with the module's name.
pub mod lut;
mod mix;
mod oswords;
mod parts;
mod ports;
mod schedule;
mod switching;
mod synth;
mod validate;

// The mix and its parts.
pub use mix::{
    expand_names, load, parse, toml_words, Branch, Channel, LinkKind, LinkSpec, Mix, MixError,
    ModeSelect, Modes, Trigger, When, MAX_BAUD_ERROR_PCT,
};
pub use parts::{
    ns_to_cycles, volts, AdcPart, CmdBit, CnvRead, Command, MuxPart, SampleAt, SpiTiming, Start,
    Supply, TimingError,
};

// The schedule: synthesis, its independent proof, and what it promises.
pub use command::CommandSent;
pub use schedule::{
    seconds, BranchPlan, ChannelSlots, FrameGrid, Placement, SamplingInstant, Schedule,
};
pub use synth::{
    synthesize, synthesize_within, BranchDiagnosis, Infeasible, Verdict, SEARCH_BUDGET,
};
pub use validate::validate;

// Modes: when a switch takes effect, and how long a reaction takes.
pub use switching::{first_instant, pin_latency, trigger_latency, TriggerLatency};

// The audit, and the fixes offered for an infeasible mix.
pub use audit::{
    AuditReport, BranchAudit, ChannelAudit, CommandAudit, FinerGrid, Headroom, Limit, ModeAudit,
    ModeBranch, ModeChannel, ModeLink, PartAudit, TriggerAudit,
};
pub use fixes::{
    search as search_fixes, search_link as search_fixes_link,
    search_unloadable as search_fixes_unloadable, Change, Fix, FixSearch,
};

// The pin contract of `slotforge_top`. `limits` stays a namespace: its
// `MAX_*` are the contract's, apart from the gateware's own (`hdl::MAX_*`).
pub use ports::{
    limits, manifest, Dir, Layout, LinkPort, ModePort, Pins, Port, Role, Signal, AXIS_PORTS,
    LINK_PORTS, MODE_PORTS, MUX_SELECT_BITS, PORTS, PORT_NAMES, SAMPLE_VALUE_BITS, TOP_MODULE,
};

// The FPGA parts slotforge synthesizes for.
pub use fpga::{Constraints, Family, Fpga, Toolchain};

// The link to the host, planned from the schedule.
pub use hostlink::{
    merged_frame, merged_run, plan as plan_link, switch_backlog, LinkInfeasible, LinkPlan,
    PacketInstants, SwitchFifo,
};

// What the OS says about a user's file, in words.
pub use oswords::{io_words, write_words};

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`), so they are reached from the integration tests
/// here.  Not an API: no other crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::audit::{alias_hz, compact, least};
    pub use crate::fixes::{apply, cost, feasible, Edit, CANDIDATE_BUDGET};
    pub use crate::hostlink::plan_one;
    pub use crate::synth::{on_grid, one_mode};
}
