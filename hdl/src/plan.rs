//! From a `lut_gen::Schedule` to the numbers the gateware is built from
//! (pure Rust, no rust-hdl): limits, per-branch ROM images, reset values.

use lut_gen::Schedule;

use crate::HdlError;

/// Branch lanes of the fixed-maximum core.
pub const MAX_BRANCHES: usize = 8;
pub const MAX_CHANNELS: usize = 256;
pub const MAX_DEVICES_PER_BRANCH: usize = 32;
pub const MAX_DEVICES: usize = 64;
pub const MAX_FRAME_SLOTS: u64 = 1 << crate::core::SLOT_BITS;
pub const MAX_SLOT_CYCLES: u64 = 1 << crate::core::CNT_BITS;
pub const MAX_SCLK_DIV: u64 = (1 << crate::core::PH_BITS) - 1;

/// The SPI timing of one or more branches: one shared sequencer each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeqTiming {
    pub sclk_div: u64,
    pub sclk_half: u64,
    pub setup_cycles: u64,
    pub read_cycles: u64,
}

/// One branch's slot ROM and numbers.
#[derive(Debug, Clone)]
pub struct BranchRom {
    /// `2^addr_bits` words of [`BranchRom::word_bits`] bits, for frame slot
    /// `u`: `{conv, ch[ch_bits], msel[3], mdev[dev_bits]}`: whether the branch
    /// converts in slot `u` and which channel, and the mux select/device of
    /// the branch's first instant at slot `u` or later (cyclic), i.e. what
    /// the mux addresses after the first cycle of slot `u - 1`.
    pub words: Vec<u32>,
    pub addr_bits: usize,
    pub ch_bits: usize,
    pub dev_bits: usize,
    /// Index of the branch's SPI sequencer in [`Plan::seqs`].
    pub seq: usize,
    pub reset_sel: u32,
    /// One-hot mux enable of the first instant of frame 0 (0 if the branch never converts).
    pub reset_en: u64,
    /// Whether the branch converts in slot 0.
    pub conv0: bool,
    pub devices: usize,
    /// First device bit of this branch in the `mux_en` port.
    pub en_offset: usize,
}

impl BranchRom {
    pub fn word_bits(&self) -> usize {
        1 + self.ch_bits + 3 + self.dev_bits
    }

    /// Pack one ROM word.
    pub fn word(&self, conv: bool, ch: u32, sel: u32, dev: u32) -> u32 {
        let (cw, dw) = (self.ch_bits, self.dev_bits);
        ((conv as u32) << (cw + 3 + dw)) | (ch << (3 + dw)) | (sel << dw) | dev
    }
}

#[derive(Debug, Clone)]
pub struct Plan {
    pub slot_cycles: u64,
    pub frame_slots: u64,
    pub channel_bits: u32,
    pub seqs: Vec<SeqTiming>,
    pub branches: Vec<BranchRom>,
}

pub fn addr_bits(frame_slots: u64) -> usize {
    let mut b = 1;
    while (1u64 << b) < frame_slots {
        b += 1;
    }
    b
}

fn unsupported(msg: String) -> HdlError {
    HdlError::Unsupported(msg)
}

pub fn plan(s: &Schedule) -> Result<Plan, HdlError> {
    let g = &s.grid;
    let nb = s.branches.len();
    if nb == 0 || nb > MAX_BRANCHES {
        return Err(unsupported(format!(
            "{nb} branches: the gateware supports 1 to {MAX_BRANCHES}"
        )));
    }
    if s.channels.is_empty() || s.channels.len() > MAX_CHANNELS {
        return Err(unsupported(format!(
            "{} channels: the gateware supports 1 to {MAX_CHANNELS}",
            s.channels.len()
        )));
    }
    if g.frame_slots == 0 || g.frame_slots > MAX_FRAME_SLOTS {
        return Err(unsupported(format!(
            "{} slots per frame: the full-frame slot ROM holds at most {MAX_FRAME_SLOTS}",
            g.frame_slots
        )));
    }
    if g.slot_cycles < 2 || g.slot_cycles > MAX_SLOT_CYCLES {
        return Err(unsupported(format!(
            "{} cycles per slot: the slot counter supports 2 to {MAX_SLOT_CYCLES}",
            g.slot_cycles
        )));
    }
    if s.frame_table.len() as u64 != g.frame_slots * nb as u64 {
        return Err(unsupported(
            "frame table size does not match the grid".into(),
        ));
    }
    let total_devices: usize = s.branches.iter().map(|b| b.mux_devices as usize).sum();
    if total_devices > MAX_DEVICES {
        return Err(unsupported(format!(
            "{total_devices} mux devices in total: the gateware supports at most {MAX_DEVICES}"
        )));
    }
    let aw = addr_bits(g.frame_slots);
    let cw = s.channel_bits().max(1) as usize;
    let mut seqs: Vec<SeqTiming> = Vec::new();
    let mut branches = Vec::with_capacity(nb);
    let mut en_offset = 0usize;
    for (b, bp) in s.branches.iter().enumerate() {
        let adc = &s.mix.branches[b].adc;
        if adc.sclk_per_conversion != 16 || adc.bits != 14 || adc.leading_zeros != 2 {
            return Err(unsupported(format!(
                "branch {}: ADC {} is not a 16-clock, 2-leading-zero, 14-bit SPI ADC",
                bp.name, adc.name
            )));
        }
        let spi = &bp.spi;
        if spi.sclk_div < 2 || spi.sclk_div > MAX_SCLK_DIV || spi.sclk_div % 2 != 0 {
            return Err(unsupported(format!(
                "branch {}: SCLK divider {} must be even and in 2..={MAX_SCLK_DIV}",
                bp.name, spi.sclk_div
            )));
        }
        if spi.sclk_half * 2 != spi.sclk_div {
            return Err(unsupported(format!(
                "branch {}: sclk_half {} is not sclk_div/2",
                bp.name, spi.sclk_half
            )));
        }
        if spi.setup_cycles < 1 || spi.setup_cycles > spi.sclk_div {
            return Err(unsupported(format!(
                "branch {}: CS setup of {} cycles must be within 1..=sclk_div ({})",
                bp.name, spi.setup_cycles, spi.sclk_div
            )));
        }
        if spi.read_cycles != spi.setup_cycles + 16 * spi.sclk_div {
            return Err(unsupported(format!(
                "branch {}: read_cycles {} != setup + 16 * sclk_div",
                bp.name, spi.read_cycles
            )));
        }
        // The branch's shift register and channel register hold a result
        // until the merger takes it (at most nb - 1 cycles after the
        // completion at t + R); the next slot must not start before.
        if spi.read_cycles + nb as u64 > g.slot_cycles {
            return Err(unsupported(format!(
                "branch {}: a conversion ({} cycles) plus the merger's {nb} cycles does not fit in a slot ({} cycles)",
                bp.name, spi.read_cycles, g.slot_cycles
            )));
        }
        let devices = bp.mux_devices as usize;
        if devices == 0 || devices > MAX_DEVICES_PER_BRANCH {
            return Err(unsupported(format!(
                "branch {}: {devices} mux devices; the gateware supports 1 to {MAX_DEVICES_PER_BRANCH}",
                bp.name
            )));
        }
        let timing = SeqTiming {
            sclk_div: spi.sclk_div,
            sclk_half: spi.sclk_half,
            setup_cycles: spi.setup_cycles,
            read_cycles: spi.read_cycles,
        };
        let seq = match seqs.iter().position(|t| *t == timing) {
            Some(i) => i,
            None => {
                seqs.push(timing);
                seqs.len() - 1
            }
        };
        let slots: Vec<Option<usize>> = (0..g.frame_slots).map(|t| s.at(t, b)).collect();
        for c in slots.iter().flatten() {
            let ch = &s.channels[*c];
            if ch.select > 7 || ch.device as usize >= devices {
                return Err(unsupported(format!(
                    "branch {}: channel device {} select {} outside the branch's muxes",
                    bp.name, ch.device, ch.select
                )));
            }
        }
        // next[u]: the channel of the first instant at slot u or later (cyclic).
        let n = slots.len();
        let mut next: Vec<Option<usize>> = vec![None; n];
        let mut cur: Option<usize> = None;
        for u in (0..2 * n).rev() {
            if let Some(c) = slots[u % n] {
                cur = Some(c);
            }
            if u < n {
                next[u] = cur;
            }
        }
        let mut rom = BranchRom {
            words: vec![],
            addr_bits: aw,
            ch_bits: cw,
            dev_bits: addr_bits(devices as u64),
            seq,
            reset_sel: 0,
            reset_en: 0,
            conv0: slots[0].is_some(),
            devices,
            en_offset,
        };
        let mut words = vec![0u32; 1 << aw];
        for u in 0..n {
            let (sel, dev) = match next[u] {
                Some(c) => (s.channels[c].select, s.channels[c].device),
                None => (0, 0),
            };
            let ch = slots[u].unwrap_or(0) as u32;
            words[u] = rom.word(slots[u].is_some(), ch, sel, dev);
        }
        rom.words = words;
        if let Some(c) = next[0] {
            rom.reset_sel = s.channels[c].select;
            rom.reset_en = 1u64 << s.channels[c].device;
        }
        branches.push(rom);
        en_offset += devices;
    }
    Ok(Plan {
        slot_cycles: g.slot_cycles,
        frame_slots: g.frame_slots,
        channel_bits: s.channel_bits(),
        seqs,
        branches,
    })
}
