//! Output pins of `slotforge_top` in one cycle, and where each branch's bits sit.

use lut_gen::Schedule;
use serde::Serialize;

/// The value of every output port of `slotforge_top` in one cycle.
///
/// Same fields as `hdl::Pins`; bit `b` of `cs_n`/`sclk` is branch `b`,
/// `mux_sel[3b+2:3b]` is branch `b`'s address, `mux_en` holds the branches'
/// devices in branch order (see `docs/timing.md`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize)]
pub struct Pins {
    pub cs_n: u8,
    pub sclk: u8,
    pub mux_sel: u32,
    pub mux_en: u64,
    pub sample_valid: bool,
    pub sample_channel: u16,
    pub sample_value: u16,
}

/// The signals the checker names in its reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Signal {
    CsN(usize),
    Sclk(usize),
    MuxSel(usize),
    MuxEn(usize),
    Miso(usize),
    SampleValid,
    SampleChannel,
    SampleValue,
}

impl Signal {
    /// The port-level name, e.g. `adc_cs_n[1]`, `mux_sel[5:3]`.
    pub fn name(&self, layout: &Layout) -> String {
        match *self {
            Signal::CsN(b) => format!("adc_cs_n[{b}]"),
            Signal::Sclk(b) => format!("adc_sclk[{b}]"),
            Signal::Miso(b) => format!("adc_miso[{b}]"),
            Signal::MuxSel(b) => format!("mux_sel[{}:{}]", 3 * b + 2, 3 * b),
            Signal::MuxEn(b) => {
                let (lo, n) = (layout.en_lo[b], layout.en_n[b]);
                if n == 1 {
                    format!("mux_en[{lo}]")
                } else {
                    format!("mux_en[{}:{lo}]", lo + n - 1)
                }
            }
            Signal::SampleValid => "sample_valid".into(),
            Signal::SampleChannel => "sample_channel".into(),
            Signal::SampleValue => "sample_value".into(),
        }
    }

    /// This signal's value in `p`.
    pub fn get(&self, layout: &Layout, p: &Pins) -> u64 {
        match *self {
            Signal::CsN(b) => (p.cs_n >> b) as u64 & 1,
            Signal::Sclk(b) => (p.sclk >> b) as u64 & 1,
            Signal::Miso(_) => 0,
            Signal::MuxSel(b) => layout.sel(p, b) as u64,
            Signal::MuxEn(b) => layout.en(p, b),
            Signal::SampleValid => p.sample_valid as u64,
            Signal::SampleChannel => p.sample_channel as u64,
            Signal::SampleValue => p.sample_value as u64,
        }
    }

    /// The branch this signal belongs to, if any.
    pub fn branch(&self) -> Option<usize> {
        match *self {
            Signal::CsN(b)
            | Signal::Sclk(b)
            | Signal::MuxSel(b)
            | Signal::MuxEn(b)
            | Signal::Miso(b) => Some(b),
            _ => None,
        }
    }
}

/// The top module's ports in the order of docs/timing.md's port table.
pub const PORT_NAMES: [&str; 10] = [
    "clk",
    "rst",
    "adc_miso",
    "adc_cs_n",
    "adc_sclk",
    "mux_sel",
    "mux_en",
    "sample_valid",
    "sample_channel",
    "sample_value",
];

/// Port bit layout of a schedule's top module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    pub branches: usize,
    /// First `mux_en` bit of each branch.
    pub en_lo: Vec<u32>,
    /// `mux_en` bits of each branch.
    pub en_n: Vec<u32>,
    /// Total mux devices (width of `mux_en`).
    pub mux_devices: u32,
    /// Width of `sample_channel`.
    pub channel_bits: u32,
    /// `(branch, device, select)` -> channel, as `lookup[branch][device * 8 + select]`.
    pub lookup: Vec<Vec<Option<u16>>>,
}

impl Layout {
    /// Width of each port of [`PORT_NAMES`], in the same order.
    pub fn port_widths(&self) -> [u32; 10] {
        let nb = self.branches as u32;
        [
            1,
            1,
            nb,
            nb,
            nb,
            3 * nb,
            self.mux_devices,
            1,
            self.channel_bits,
            14,
        ]
    }

    pub fn new(s: &Schedule) -> Layout {
        let nb = s.branches.len();
        assert!(nb <= 8, "at most 8 branches are supported by the checker");
        let mut en_lo = Vec::with_capacity(nb);
        let mut en_n = Vec::with_capacity(nb);
        let mut acc = 0;
        for b in &s.branches {
            en_lo.push(acc);
            en_n.push(b.mux_devices.max(1));
            acc += b.mux_devices.max(1);
        }
        assert!(
            acc <= 64,
            "at most 64 mux devices are supported by the checker"
        );
        let mut lookup: Vec<Vec<Option<u16>>> =
            (0..nb).map(|b| vec![None; en_n[b] as usize * 8]).collect();
        for (c, ch) in s.channels.iter().enumerate() {
            let b = s.mix.channels[c].branch;
            let i = (ch.device * 8 + ch.select) as usize;
            if i < lookup[b].len() {
                lookup[b][i] = Some(c as u16);
            }
        }
        Layout {
            branches: nb,
            en_lo,
            en_n,
            mux_devices: acc,
            channel_bits: s.channel_bits(),
            lookup,
        }
    }

    #[inline]
    pub fn sel(&self, p: &Pins, b: usize) -> u32 {
        (p.mux_sel >> (3 * b)) & 7
    }

    #[inline]
    pub fn en(&self, p: &Pins, b: usize) -> u64 {
        (p.mux_en >> self.en_lo[b]) & ((1u64 << self.en_n[b]) - 1)
    }

    /// Branch `b`'s mux pins addressing `(device, select)`.
    pub fn set_mux(&self, p: &mut Pins, b: usize, device: u32, select: u32) {
        p.mux_sel = (p.mux_sel & !(7 << (3 * b))) | ((select & 7) << (3 * b));
        let mask = ((1u64 << self.en_n[b]) - 1) << self.en_lo[b];
        p.mux_en = (p.mux_en & !mask) | ((1u64 << device) << self.en_lo[b]);
    }

    /// The channel branch `b`'s mux pins select, or why none is.
    pub fn selected(&self, p: &Pins, b: usize) -> Result<u16, String> {
        let en = self.en(p, b);
        if en.count_ones() != 1 {
            return Err(format!(
                "mux_en of branch {b} is {en:#b}: not one device enabled"
            ));
        }
        let dev = en.trailing_zeros();
        let sel = self.sel(p, b);
        self.lookup[b][(dev * 8 + sel) as usize]
            .ok_or_else(|| format!("no channel on branch {b} device {dev} select {sel}"))
    }

    /// Every signal, in report order.
    pub fn signals(&self) -> Vec<Signal> {
        let mut v = Vec::new();
        for b in 0..self.branches {
            v.push(Signal::CsN(b));
            v.push(Signal::Sclk(b));
            v.push(Signal::MuxSel(b));
            v.push(Signal::MuxEn(b));
        }
        v.extend([
            Signal::SampleValid,
            Signal::SampleChannel,
            Signal::SampleValue,
        ]);
        v
    }
}
