//! The pin contract of `slotforge_top`: the one home of every port name,
//! direction, role and width, of where each branch's lanes sit in the
//! ports, of the gateware's size limits, and of `ports.json`.
//!
//! The gateware generator, the Verilog wrapper and constraints, the
//! simulation engines, the VCD reader and writer, the Icarus testbench and
//! the fault injector all read names and widths from here, so a port renamed
//! in [`PORTS`] is renamed everywhere.  It sits in lut-gen (the bottom of the
//! crate graph) because the widths are a function of the schedule alone, and
//! both sides of the contract (the gateware in `hdl`, the judge in
//! `cosim/judge`) must see it without seeing each other.
//!
//! Cycle-level behaviour of these ports: `docs/timing.md`.

use serde::Serialize;

mod mode;
pub use mode::{ModePort, MODE_PORTS};

use crate::parts::Start;
use crate::schedule::Schedule;

/// Name of the top module.
pub const TOP_MODULE: &str = "slotforge_top";

/// Bits of a mux select (8:1 multiplexers).
pub const MUX_SELECT_BITS: u32 = 3;
/// Mux inputs one select addresses per device.
pub const INPUTS_PER_DEVICE: u32 = 1 << MUX_SELECT_BITS;
/// The most bits `sample_value` can have (the widest converter word the
/// gateware carries); a mix's width is [`Layout::width`]`(Role::SampleValue)`:
/// the widest part of the mix (14 for AD7940s, 16 with an AD7685).
pub const SAMPLE_VALUE_BITS: u32 = 16;

/// What the gateware can carry: its fixed-maximum core has this many lanes.
/// `hdl` builds its core at these sizes and refuses larger mixes; the judge
/// sizes [`Pins`] from them.
pub mod limits {
    /// Branch lanes (one SPI port and one mux select each).
    pub const MAX_BRANCHES: usize = 16;
    /// Channels (`sample_channel` is `log2(MAX_CHANNELS)` bits wide in the core).
    pub const MAX_CHANNELS: usize = 1024;
    /// Mux devices of one branch.
    pub const MAX_DEVICES_PER_BRANCH: usize = 32;
    /// Mux devices over all branches (`mux_en` bits in the core): 1,024
    /// channels of 8:1 muxes.
    pub const MAX_DEVICES: usize = 128;
}

/// What a port is for; the index into [`PORTS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Role {
    Clock,
    Reset,
    Miso,
    CsN,
    Sclk,
    /// `adc_mosi`: the command word of a converter that takes one; one bit
    /// per such branch, absent from a mix without one.
    Mosi,
    MuxSel,
    MuxEn,
    SampleValid,
    SampleChannel,
    SampleValue,
}

/// Direction seen from the gateware.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Dir {
    In,
    Out,
}

impl Dir {
    /// `ports.json`'s spelling.
    pub fn short(self) -> &'static str {
        match self {
            Dir::In => "in",
            Dir::Out => "out",
        }
    }

    /// Verilog's spelling.
    pub fn verilog(self) -> &'static str {
        match self {
            Dir::In => "input",
            Dir::Out => "output",
        }
    }
}

/// One port of `slotforge_top`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Port {
    pub role: Role,
    pub name: &'static str,
    pub dir: Dir,
    /// Declared as a vector (`[w-1:0]`) even when one bit wide.
    pub vector: bool,
    /// The role's key in `ports.json` (`"cs_n"` in a branch, `"valid"` in
    /// `"sample"`), also the name of a branch's lane in a waveform's
    /// per-branch view.
    pub key: &'static str,
}

/// The ports of `slotforge_top`, in the order of docs/timing.md's port
/// table (and of the Verilog port list, `ports.json` and the PCF).
pub const PORTS: [Port; 11] = [
    port(Role::Clock, "clk", Dir::In, false, "clock"),
    port(Role::Reset, "rst", Dir::In, false, "reset"),
    port(Role::Miso, "adc_miso", Dir::In, true, "miso"),
    port(Role::CsN, "adc_cs_n", Dir::Out, true, "cs_n"),
    port(Role::Sclk, "adc_sclk", Dir::Out, true, "sclk"),
    port(Role::Mosi, "adc_mosi", Dir::Out, true, "mosi"),
    port(Role::MuxSel, "mux_sel", Dir::Out, true, "mux_sel"),
    port(Role::MuxEn, "mux_en", Dir::Out, true, "mux_en"),
    port(Role::SampleValid, "sample_valid", Dir::Out, false, "valid"),
    port(
        Role::SampleChannel,
        "sample_channel",
        Dir::Out,
        true,
        "channel",
    ),
    port(Role::SampleValue, "sample_value", Dir::Out, true, "value"),
];

/// The names of [`PORTS`], in the same order.
pub const PORT_NAMES: [&str; 11] = {
    let mut n = [""; 11];
    let mut i = 0;
    while i < PORTS.len() {
        n[i] = PORTS[i].name;
        i += 1;
    }
    n
};

const fn port(role: Role, name: &'static str, dir: Dir, vector: bool, key: &'static str) -> Port {
    Port {
        role,
        name,
        dir,
        vector,
        key,
    }
}

impl Role {
    /// Every role, in port order.
    pub const ALL: [Role; 11] = [
        Role::Clock,
        Role::Reset,
        Role::Miso,
        Role::CsN,
        Role::Sclk,
        Role::Mosi,
        Role::MuxSel,
        Role::MuxEn,
        Role::SampleValid,
        Role::SampleChannel,
        Role::SampleValue,
    ];

    pub const fn port(self) -> &'static Port {
        &PORTS[self as usize]
    }

    /// The port's name, e.g. `adc_cs_n`.
    pub const fn name(self) -> &'static str {
        self.port().name
    }

    /// The role's key in `ports.json`, e.g. `cs_n`.
    pub const fn key(self) -> &'static str {
        self.port().key
    }

    /// The roles with one lane per branch, in port order.
    pub const LANES: [Role; 6] = [
        Role::Miso,
        Role::CsN,
        Role::Sclk,
        Role::Mosi,
        Role::MuxSel,
        Role::MuxEn,
    ];
}

impl Pins {
    /// Every pin low, in a `const` (`Default` is not): as an unknown-bits
    /// mask (`xz`), no bit of any port is `x` or `z`.
    pub const LOW: Pins = Pins {
        cs_n: 0,
        sclk: 0,
        mosi: 0,
        mux_sel: 0,
        mux_en: 0,
        sample_valid: false,
        sample_channel: 0,
        sample_value: 0,
        link_tx: false,
        link_overflow: false,
        axis_tdata: 0,
        axis_tvalid: false,
        axis_tlast: false,
        axis_tready: false,
        mode_sel: 0,
        mode: 0,
    };

    /// The value of output port `r` (inputs read as 0); `u128` because
    /// `mux_en` has up to [`limits::MAX_DEVICES`] bits.
    #[inline]
    pub fn value(&self, r: Role) -> u128 {
        match r {
            Role::Clock | Role::Reset | Role::Miso => 0,
            Role::CsN => self.cs_n as u128,
            Role::Sclk => self.sclk as u128,
            Role::Mosi => self.mosi as u128,
            Role::MuxSel => self.mux_sel as u128,
            Role::MuxEn => self.mux_en,
            Role::SampleValid => self.sample_valid as u128,
            Role::SampleChannel => self.sample_channel as u128,
            Role::SampleValue => self.sample_value as u128,
        }
    }
}

/// The value of every output port of `slotforge_top` in one cycle.
///
/// Bit `b` of `cs_n`/`sclk` is branch `b`; `mux_sel` holds the selects and
/// `mux_en` the devices of the branches that have a multiplexer, in branch
/// order (`mux_sel[3b+2:3b]` is branch `b`'s select when every branch has
/// one; see [`Layout`]).  Sized for [`limits`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize)]
pub struct Pins {
    pub cs_n: u16,
    pub sclk: u16,
    /// `adc_mosi`: bit `i` is the `i`-th branch with a command word
    /// ([`Layout::mosi_lo`]).
    pub mosi: u16,
    pub mux_sel: u64,
    pub mux_en: u128,
    pub sample_valid: bool,
    pub sample_channel: u16,
    pub sample_value: u16,
    /// The link's serial line (`link_tx`; a mix with a `[link]` only).
    pub link_tx: bool,
    /// The link FIFO's sticky overflow flag (`link_overflow`).
    pub link_overflow: bool,
    /// An AXI4-Stream link's master outputs and the slave's `tready` (an
    /// input, recorded so the judge sees the handshake of every cycle).
    pub axis_tdata: u8,
    pub axis_tvalid: bool,
    pub axis_tlast: bool,
    pub axis_tready: bool,
    /// A mix with modes: `mode_sel` (an input, pin select only, recorded so
    /// the judge sees the request of every cycle) and `mode`, the mode in
    /// force (docs/timing.md, "Mode switches"); 0 without modes.
    pub mode_sel: u8,
    pub mode: u8,
}

/// A port of the link to the host: present only when the mix has a
/// `[link]`, after the ports of [`PORTS`], so a mix without one keeps
/// exactly today's ports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkPort {
    pub name: &'static str,
    pub dir: Dir,
    /// The port's key under `"link"` in `ports.json`.
    pub key: &'static str,
    /// Bits (1: a scalar port).
    pub width: u32,
    /// The signal it carries.
    pub signal: Signal,
}

/// The FIFO's sticky overflow flag, a port of either link.
const OVERFLOW: LinkPort = LinkPort {
    name: "link_overflow",
    dir: Dir::Out,
    key: "overflow",
    width: 1,
    signal: Signal::LinkOverflow,
};

/// The UART link's ports: the serial line and the FIFO's overflow flag.
pub const LINK_PORTS: [LinkPort; 2] = [
    LinkPort {
        name: "link_tx",
        dir: Dir::Out,
        key: "tx",
        width: 1,
        signal: Signal::LinkTx,
    },
    OVERFLOW,
];

/// The AXI4-Stream link's ports (docs/packet-format.md, "AXI4-Stream"):
/// byte beats, the handshake, and the FIFO's overflow flag.
pub const AXIS_PORTS: [LinkPort; 5] = [
    LinkPort {
        name: "m_axis_tdata",
        dir: Dir::Out,
        key: "tdata",
        width: 8,
        signal: Signal::AxisTdata,
    },
    LinkPort {
        name: "m_axis_tvalid",
        dir: Dir::Out,
        key: "tvalid",
        width: 1,
        signal: Signal::AxisTvalid,
    },
    LinkPort {
        name: "m_axis_tlast",
        dir: Dir::Out,
        key: "tlast",
        width: 1,
        signal: Signal::AxisTlast,
    },
    LinkPort {
        name: "m_axis_tready",
        dir: Dir::In,
        key: "tready",
        width: 1,
        signal: Signal::AxisTready,
    },
    OVERFLOW,
];

const _: () = {
    assert!(
        limits::MAX_BRANCHES <= 16,
        "Pins::cs_n / sclk hold one bit per branch"
    );
    assert!(limits::MAX_BRANCHES * MUX_SELECT_BITS as usize <= 64);
    assert!(limits::MAX_DEVICES <= 128);
    assert!(
        limits::MAX_DEVICES_PER_BRANCH < 64,
        "Layout::en returns u64"
    );
    assert!(limits::MAX_CHANNELS <= 1 << 16);
    assert!(SAMPLE_VALUE_BITS <= 16);
};

/// A signal of one branch or of the sample stream, as the checker and the
/// fault injector name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Signal {
    CsN(usize),
    Sclk(usize),
    Mosi(usize),
    MuxSel(usize),
    MuxEn(usize),
    Miso(usize),
    SampleValid,
    SampleChannel,
    SampleValue,
    /// `link_tx`.
    LinkTx,
    /// `link_overflow`.
    LinkOverflow,
    /// `m_axis_tdata`, `m_axis_tvalid`, `m_axis_tlast`, `m_axis_tready`.
    AxisTdata,
    AxisTvalid,
    AxisTlast,
    AxisTready,
}

impl Signal {
    /// The port role of a signal of [`PORTS`]; `None` for the link's.
    pub fn role(&self) -> Option<Role> {
        Some(match *self {
            Signal::CsN(_) => Role::CsN,
            Signal::Sclk(_) => Role::Sclk,
            Signal::Mosi(_) => Role::Mosi,
            Signal::MuxSel(_) => Role::MuxSel,
            Signal::MuxEn(_) => Role::MuxEn,
            Signal::Miso(_) => Role::Miso,
            Signal::SampleValid => Role::SampleValid,
            Signal::SampleChannel => Role::SampleChannel,
            Signal::SampleValue => Role::SampleValue,
            Signal::LinkTx
            | Signal::LinkOverflow
            | Signal::AxisTdata
            | Signal::AxisTvalid
            | Signal::AxisTlast
            | Signal::AxisTready => return None,
        })
    }

    /// The port-level name, e.g. `adc_cs_n[1]`, `mux_sel[5:3]`.
    pub fn name(&self, layout: &Layout) -> String {
        match (self.branch(), self.role()) {
            (Some(b), Some(r)) => layout.lane(r, b),
            (_, Some(r)) => r.name().to_string(),
            (_, None) => LINK_PORTS
                .iter()
                .chain(&AXIS_PORTS)
                .find(|p| p.signal == *self)
                .map_or("", |p| p.name)
                .to_string(),
        }
    }

    /// This signal's value in `p`.
    pub fn get(&self, layout: &Layout, p: &Pins) -> u64 {
        match *self {
            Signal::CsN(b) => (p.cs_n >> b) as u64 & 1,
            Signal::Sclk(b) => (p.sclk >> b) as u64 & 1,
            Signal::Mosi(b) => layout.mosi(p, b) as u64,
            Signal::Miso(_) => 0,
            Signal::MuxSel(b) => layout.sel(p, b) as u64,
            Signal::MuxEn(b) => layout.en(p, b),
            Signal::SampleValid => p.sample_valid as u64,
            Signal::SampleChannel => p.sample_channel as u64,
            Signal::SampleValue => p.sample_value as u64,
            Signal::LinkTx => p.link_tx as u64,
            Signal::LinkOverflow => p.link_overflow as u64,
            Signal::AxisTdata => p.axis_tdata as u64,
            Signal::AxisTvalid => p.axis_tvalid as u64,
            Signal::AxisTlast => p.axis_tlast as u64,
            Signal::AxisTready => p.axis_tready as u64,
        }
    }

    /// The branch this signal belongs to, if any.
    pub fn branch(&self) -> Option<usize> {
        match *self {
            Signal::CsN(b)
            | Signal::Sclk(b)
            | Signal::Mosi(b)
            | Signal::MuxSel(b)
            | Signal::MuxEn(b)
            | Signal::Miso(b) => Some(b),
            _ => None,
        }
    }
}

/// The port bit layout of a schedule's top module: widths, and where each
/// branch's lanes sit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    pub branches: usize,
    /// Whether each branch has a multiplexer.  A branch with `mux = "none"`
    /// has no mux lanes at all: no `mux_sel` bits, no `mux_en` bits, so a
    /// board never routes pins that connect to nothing.
    pub muxed: Vec<bool>,
    /// First `mux_sel` bit of each branch ([`MUX_SELECT_BITS`] wide when
    /// the branch has a mux, none otherwise).
    pub sel_lo: Vec<u32>,
    /// First `mux_en` bit of each branch.
    pub en_lo: Vec<u32>,
    /// `mux_en` bits of each branch (at least one with a mux, 0 without).
    pub en_n: Vec<u32>,
    /// Total mux devices (width of `mux_en`).
    pub mux_devices: u32,
    /// The `adc_mosi` bit of each branch whose converter takes a command
    /// word (`None`: no lane); the bits count up in branch order.
    pub mosi_lo: Vec<Option<u32>>,
    /// Width of `sample_channel`.
    pub channel_bits: u32,
    /// Width of `sample_value`: the widest part's data bits.
    pub value_bits: u32,
    /// How each branch's conversion pin (the `adc_cs_n` lane) works: CS
    /// (active low) or CNV (active high).
    pub starts: Vec<Start>,
    /// `(branch, device, select)` -> channel, as `lookup[branch][device * 8 + select]`.
    pub lookup: Vec<Vec<Option<u16>>>,
    /// The mix has a link to the host: [`Layout::link_ports`] follow [`PORTS`].
    pub link: bool,
    /// The link is AXI4-Stream ([`AXIS_PORTS`]), not a UART ([`LINK_PORTS`]).
    pub axis: bool,
    /// Bits of the mode ports ([`Layout::mode_ports`]); 0: no modes.
    pub mode_bits: u32,
    /// Modes chosen by the `mode_sel` pin (`select = "pin"`).
    pub mode_pin: bool,
}

impl Layout {
    /// The layout of `s`'s top module.
    ///
    /// # Panics
    /// When `s` exceeds [`limits`]; callers that take user mixes check
    /// [`Layout::fits`] first.
    pub fn new(s: &Schedule) -> Layout {
        if let Err(m) = Layout::fits_limits(s) {
            panic!("{m}");
        }
        let nb = s.branches.len();
        let muxed: Vec<bool> = s
            .mix
            .branches
            .iter()
            .map(|b| b.mux.select_bits > 0)
            .collect();
        let (mut sel_lo, mut en_lo, mut en_n) = (vec![], vec![], vec![]);
        let (mut sel, mut acc) = (0, 0);
        for (b, bp) in s.branches.iter().enumerate() {
            let n = if muxed[b] { bp.mux_devices.max(1) } else { 0 };
            sel_lo.push(sel);
            en_lo.push(acc);
            en_n.push(n);
            sel += if muxed[b] { MUX_SELECT_BITS } else { 0 };
            acc += n;
        }
        let mut lookup: Vec<Vec<Option<u16>>> = (0..nb)
            .map(|b| vec![None; (en_n[b].max(1) * INPUTS_PER_DEVICE) as usize])
            .collect();
        for (c, ch) in s.channels.iter().enumerate() {
            let b = s.mix.channels[c].branch;
            let i = (ch.device * INPUTS_PER_DEVICE + ch.select) as usize;
            // Chain members share an address: it names the conversion's lead.
            if i < lookup[b].len() && lookup[b][i].is_none() {
                lookup[b][i] = Some(c as u16);
            }
        }
        Layout {
            branches: nb,
            muxed,
            sel_lo,
            en_lo,
            en_n,
            mux_devices: acc,
            mosi_lo: (0..nb)
                .scan(0u32, |n, b| {
                    Some(s.has_command(b).then(|| {
                        *n += 1;
                        *n - 1
                    }))
                })
                .collect(),
            channel_bits: s.channel_bits(),
            value_bits: s.mix.branches.iter().map(|b| b.adc.bits).max().unwrap_or(1),
            starts: s.mix.branches.iter().map(|b| b.adc.start).collect(),
            lookup,
            link: s.mix.link.is_some(),
            axis: s
                .mix
                .link
                .is_some_and(|l| l.kind == crate::mix::LinkKind::Axis),
            mode_bits: s.mix.modes.as_ref().map_or(0, |m| m.select_bits()),
            mode_pin: s
                .mix
                .modes
                .as_ref()
                .is_some_and(|m| m.select == crate::mix::ModeSelect::Pin),
        }
    }

    /// The link's ports after [`PORTS`]: none without a `[link]`.
    pub fn link_ports(&self) -> &'static [LinkPort] {
        match (self.link, self.axis) {
            (false, _) => &[],
            (true, false) => &LINK_PORTS,
            (true, true) => &AXIS_PORTS,
        }
    }

    /// Whether the gateware and the judge take `s`: it fits [`limits`]
    /// (converters with a command word included: the gateware drives
    /// `adc_mosi`).
    pub fn fits(s: &Schedule) -> Result<(), String> {
        Layout::fits_limits(s)
    }

    /// Whether `s` fits the gateware's [`limits`], or which limit it exceeds.
    fn fits_limits(s: &Schedule) -> Result<(), String> {
        use limits::*;
        let nb = s.branches.len();
        if nb == 0 || nb > MAX_BRANCHES {
            return Err(format!(
                "{nb} branches: the gateware supports 1 to {MAX_BRANCHES}"
            ));
        }
        if s.channels.is_empty() || s.channels.len() > MAX_CHANNELS {
            return Err(format!(
                "{} channels: the gateware supports 1 to {MAX_CHANNELS}",
                s.channels.len()
            ));
        }
        if let Some(b) = s
            .branches
            .iter()
            .find(|b| b.mux_devices as usize > MAX_DEVICES_PER_BRANCH)
        {
            return Err(format!(
                "branch {}: {} mux devices: the gateware supports at most {MAX_DEVICES_PER_BRANCH} per branch",
                b.name, b.mux_devices
            ));
        }
        let total: usize = s.branches.iter().map(|b| b.mux_devices as usize).sum();
        if total > MAX_DEVICES {
            return Err(format!(
                "{total} mux devices in total: the gateware supports at most {MAX_DEVICES}"
            ));
        }
        Ok(())
    }

    /// Width in bits of the port with role `r`.
    pub fn width(&self, r: Role) -> u32 {
        let nb = self.branches as u32;
        match r {
            Role::Clock | Role::Reset | Role::SampleValid => 1,
            Role::Miso | Role::CsN | Role::Sclk => nb,
            Role::Mosi => self.mosi_lo.iter().flatten().count() as u32,
            Role::MuxSel => MUX_SELECT_BITS * self.muxed.iter().filter(|&&m| m).count() as u32,
            Role::MuxEn => self.mux_devices,
            Role::SampleChannel => self.channel_bits,
            Role::SampleValue => self.value_bits,
        }
    }

    /// Width of each port of [`PORTS`], in the same order (0: a port the
    /// top does not have, see [`Layout::has`]).
    pub fn port_widths(&self) -> [u32; 11] {
        Role::ALL.map(|r| self.width(r))
    }

    /// Whether the top has port `r`: `mux_sel` and `mux_en` exist only when
    /// some branch has a multiplexer.
    pub fn has(&self, r: Role) -> bool {
        self.width(r) > 0
    }

    /// The ports of [`PORTS`] the top has, in port order.
    pub fn ports(&self) -> impl Iterator<Item = &'static Port> + '_ {
        PORTS.iter().filter(|p| self.has(p.role))
    }

    /// Whether branch `b` has a lane of port `r`: every branch has its SPI
    /// lanes, only a branch with a multiplexer has mux lanes.
    pub fn has_lane(&self, r: Role, b: usize) -> bool {
        match r {
            Role::Miso | Role::CsN | Role::Sclk => true,
            Role::MuxSel | Role::MuxEn => self.muxed[b],
            Role::Mosi => self.mosi_lo[b].is_some(),
            _ => false,
        }
    }

    /// The lanes of branch `b`, in the order of [`Role::LANES`].
    pub fn lanes(&self, b: usize) -> impl Iterator<Item = Role> + '_ {
        Role::LANES
            .into_iter()
            .filter(move |&r| self.has_lane(r, b))
    }

    /// The name of branch `b`'s lane of port `r` in `ports.json` and in a
    /// waveform's per-branch view: the role's key, except that the
    /// `adc_cs_n` lane of a CNV-started part (AD7685) is its `cnv`, active
    /// high, not a chip select.
    pub fn lane_key(&self, r: Role, b: usize) -> &'static str {
        match r {
            Role::CsN if self.starts[b] == Start::Cnv => "cnv",
            r => r.key(),
        }
    }

    /// The bits of port `r` that belong to branch `b`, as `(msb, lsb)`.
    ///
    /// # Panics
    /// When branch `b` has no such lane ([`Layout::has_lane`]).
    pub fn lane_bits(&self, r: Role, b: usize) -> (u32, u32) {
        assert!(self.has_lane(r, b), "branch {b} has no {} lane", r.name());
        let b32 = b as u32;
        match r {
            Role::Miso | Role::CsN | Role::Sclk => (b32, b32),
            Role::Mosi => {
                let i = self.mosi_lo[b].unwrap_or_default();
                (i, i)
            }
            Role::MuxSel => (self.sel_lo[b] + MUX_SELECT_BITS - 1, self.sel_lo[b]),
            Role::MuxEn => (self.en_lo[b] + self.en_n[b] - 1, self.en_lo[b]),
            _ => unreachable!(),
        }
    }

    /// Branch `b`'s lane of port `r` as Verilog names it: `adc_cs_n[1]`,
    /// `mux_sel[5:3]`, `mux_en[2]`.
    pub fn lane(&self, r: Role, b: usize) -> String {
        let (hi, lo) = self.lane_bits(r, b);
        if hi == lo {
            format!("{}[{lo}]", r.name())
        } else {
            format!("{}[{hi}:{lo}]", r.name())
        }
    }

    /// Every port bit with its direction, in port order (`clk`, `rst`,
    /// `adc_miso[0]`, ...): the rows of a PCF or XDC.
    pub fn bits(&self) -> Vec<(String, Dir)> {
        let mut v = Vec::new();
        for p in self.ports() {
            if p.vector {
                for i in 0..self.width(p.role) {
                    v.push((format!("{}[{i}]", p.name), p.dir));
                }
            } else {
                v.push((p.name.to_string(), p.dir));
            }
        }
        for p in self.link_ports() {
            if p.width == 1 {
                v.push((p.name.to_string(), p.dir));
            } else {
                v.extend((0..p.width).map(|i| (format!("{}[{i}]", p.name), p.dir)));
            }
        }
        // a mix with modes: its mode ports last, so a board places them too
        v.extend(self.mode_port_bits());
        v
    }

    /// Branch `b`'s `adc_mosi` bit (low for a branch without one).
    #[inline]
    pub fn mosi(&self, p: &Pins, b: usize) -> bool {
        self.mosi_lo[b].is_some_and(|i| p.mosi >> i & 1 == 1)
    }

    /// Branch `b`'s select (0 for a branch without a mux).
    #[inline]
    pub fn sel(&self, p: &Pins, b: usize) -> u32 {
        if !self.muxed[b] {
            return 0;
        }
        ((p.mux_sel >> self.sel_lo[b]) & (INPUTS_PER_DEVICE as u64 - 1)) as u32
    }

    /// Branch `b`'s device enables (0 for a branch without a mux).
    #[inline]
    pub fn en(&self, p: &Pins, b: usize) -> u64 {
        if !self.muxed[b] {
            return 0;
        }
        ((p.mux_en >> self.en_lo[b]) as u64) & ((1u64 << self.en_n[b]) - 1)
    }

    /// Branch `b`'s mux pins addressing `(device, select)`; a branch without
    /// a mux has no pins to set.
    pub fn set_mux(&self, p: &mut Pins, b: usize, device: u32, select: u32) {
        if !self.muxed[b] {
            return;
        }
        let sh = self.sel_lo[b] as usize;
        let m = INPUTS_PER_DEVICE as u64 - 1;
        p.mux_sel = (p.mux_sel & !(m << sh)) | ((select as u64 & m) << sh);
        let mask = ((1u128 << self.en_n[b]) - 1) << self.en_lo[b];
        p.mux_en = (p.mux_en & !mask) | ((1u128 << device) << self.en_lo[b]);
    }

    /// The channel branch `b`'s mux pins select, or why none is.
    pub fn selected(&self, p: &Pins, b: usize) -> Result<u16, String> {
        if !self.muxed[b] {
            // wired straight to its sensor: the one input is always selected
            return self.lookup[b][0].ok_or_else(|| format!("no channel on branch {b}"));
        }
        let en = self.en(p, b);
        if en.count_ones() != 1 {
            return Err(format!(
                "{} of branch {b} is {en:#b}: not one device enabled",
                Role::MuxEn.name()
            ));
        }
        let dev = en.trailing_zeros();
        let sel = self.sel(p, b);
        self.lookup[b][(dev * INPUTS_PER_DEVICE + sel) as usize]
            .ok_or_else(|| format!("no channel on branch {b} device {dev} select {sel}"))
    }

    /// Every signal, in report order.
    pub fn signals(&self) -> Vec<Signal> {
        let mut v = Vec::new();
        for b in 0..self.branches {
            v.push(Signal::CsN(b));
            v.push(Signal::Sclk(b));
            if self.mosi_lo[b].is_some() {
                v.push(Signal::Mosi(b));
            }
            if self.muxed[b] {
                v.push(Signal::MuxSel(b));
                v.push(Signal::MuxEn(b));
            }
        }
        v.extend([
            Signal::SampleValid,
            Signal::SampleChannel,
            Signal::SampleValue,
        ]);
        // an input (the AXIS slave's tready) is the environment's, not the design's
        v.extend(
            self.link_ports()
                .iter()
                .filter(|p| p.dir == Dir::Out)
                .map(|p| p.signal),
        );
        v
    }
}

/// `ports.json`: every port bit's role, so that any tool finds a branch's
/// signals without guessing names (`mix`, `clock_hz`, the port list and each
/// branch's SPI numbers; docs/ports.md).
pub fn manifest(s: &Schedule) -> String {
    use serde_json::json;
    let l = Layout::new(s);
    let bit = |r: Role, i: u32| format!("{}[{i}]", r.name());
    let branches: Vec<_> = s
        .branches
        .iter()
        .enumerate()
        .map(|(b, bp)| {
            let mut o = serde_json::Map::new();
            o.insert("name".into(), json!(bp.name));
            for r in l.lanes(b) {
                let v = match r {
                    Role::MuxEn => json!((0..l.en_n[b])
                        .map(|d| bit(Role::MuxEn, l.en_lo[b] + d))
                        .collect::<Vec<_>>()),
                    r => json!(l.lane(r, b)),
                };
                o.insert(l.lane_key(r, b).into(), v);
                if r == Role::CsN && l.starts[b] == Start::Cnv {
                    // The same lane, driven as the AD7685's CNV (active high).
                    o.insert("active_high".into(), json!(true));
                }
            }
            if s.mix.branches[b].adc.start == Start::Cnv || s.mix.branches[b].chain > 1 {
                o.insert("adc".into(), json!(s.mix.branches[b].adc.name));
                o.insert("chain".into(), json!(s.mix.branches[b].chain));
                o.insert("conversion_cycles".into(), json!(bp.spi.conv_cycles));
            }
            if let Some(c) = &s.mix.branches[b].adc.command {
                o.insert("adc".into(), json!(s.mix.branches[b].adc.name));
                o.insert("command".into(), json!(c.template()));
                o.insert("command_ahead".into(), json!(c.ahead));
            }
            o.insert("sclk_div".into(), json!(bp.spi.sclk_div));
            o.insert("setup_cycles".into(), json!(bp.spi.setup_cycles));
            o.insert("read_cycles".into(), json!(bp.spi.read_cycles));
            serde_json::Value::Object(o)
        })
        .collect();
    let channels: Vec<_> = s
        .channels
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mc = &s.mix.channels[i];
            json!({
                "index": i,
                "name": mc.name,
                "branch": s.branches[mc.branch].name,
                "device": c.device,
                "select": c.select,
            })
        })
        .collect();
    let mut ports: Vec<_> = l
        .ports()
        .map(|p| json!({"name": p.name, "dir": p.dir.short(), "width": l.width(p.role)}))
        .collect();
    ports.extend(
        l.link_ports()
            .iter()
            .map(|p| json!({"name": p.name, "dir": p.dir.short(), "width": p.width})),
    );
    ports.extend(
        l.mode_ports()
            .iter()
            .map(|p| json!({"name": p.name, "dir": p.dir.short(), "width": l.mode_bits})),
    );
    let mut doc = json!({
        "top": TOP_MODULE,
        "mix": s.mix.name,
        "clock": Role::Clock.name(),
        "clock_hz": s.grid.clock_hz,
        "reset": {"port": Role::Reset.name(), "active_high": true, "synchronous": true},
        "branches": branches,
        "sample": {
            Role::SampleValid.key(): Role::SampleValid.name(),
            Role::SampleChannel.key(): Role::SampleChannel.name(),
            Role::SampleValue.key(): Role::SampleValue.name(),
        },
        "channels": channels,
        "ports": ports,
    });
    if let Some(link) = manifest_link(s, &l) {
        doc["link"] = link;
    }
    if let Some(m) = mode::manifest_mode(s, &l) {
        doc["mode"] = m;
    }
    let mut t = serde_json::to_string_pretty(&doc).expect("json");
    t.push('\n');
    t
}

/// `ports.json`'s `"link"`: the link's ports by key and its line; `None`
/// without a link (or with one the mix cannot use).
fn manifest_link(s: &Schedule, l: &Layout) -> Option<serde_json::Value> {
    use serde_json::json;
    let Some(Ok(p)) = crate::hostlink::plan(s) else {
        return None;
    };
    let mut o = serde_json::Map::new();
    o.insert("kind".into(), json!(p.kind));
    for lp in l.link_ports() {
        o.insert(lp.key.into(), json!(lp.name));
    }
    if let Some(a) = p.axis() {
        o.insert("tlast_at".into(), json!(a.tlast.name()));
        o.insert("ready_within".into(), json!(a.ready_within));
    } else {
        o.insert("baud".into(), json!(p.baud));
        o.insert("baud_divider".into(), json!(p.baud_divider));
        o.insert("parity".into(), json!(p.parity));
        o.insert("stop_bits".into(), json!(p.stop_bits));
    }
    o.insert("fifo_depth".into(), json!(p.fifo_depth));
    o.insert("packet_format".into(), json!("docs/packet-format.md"));
    Some(serde_json::Value::Object(o))
}
