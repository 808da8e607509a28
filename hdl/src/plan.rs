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

/// One branch's slot ROM and SPI numbers.
#[derive(Debug, Clone)]
pub struct BranchRom {
    /// `2^addr_bits` words: bit 16 = converts in this slot, [15:8] channel
    /// converted, [7:5] mux select and [4:0] mux device of the branch's next
    /// instant after this slot (cyclic).  Zero where the branch is idle.
    pub words: Vec<u32>,
    pub addr_bits: usize,
    pub sclk_div: u64,
    pub sclk_half: u64,
    pub setup_cycles: u64,
    #[allow(dead_code)] // kept for reports and tests
    pub read_cycles: u64,
    pub reset_sel: u32,
    /// One-hot mux enable of the first instant of frame 0 (0 if the branch never converts).
    pub reset_en: u64,
    pub devices: usize,
    /// First device bit of this branch in the `mux_en` port.
    pub en_offset: usize,
}

#[derive(Debug, Clone)]
pub struct Plan {
    pub slot_cycles: u64,
    pub frame_slots: u64,
    pub channel_bits: u32,
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
        if spi.read_cycles >= g.slot_cycles {
            return Err(unsupported(format!(
                "branch {}: a conversion ({} cycles) does not end inside a slot ({} cycles)",
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
        let slots: Vec<Option<usize>> = (0..g.frame_slots).map(|t| s.at(t, b)).collect();
        let instants: Vec<usize> = (0..slots.len()).filter(|&t| slots[t].is_some()).collect();
        let mut words = vec![0u32; 1 << aw];
        for (k, &t) in instants.iter().enumerate() {
            let ch = slots[t].unwrap();
            let next_t = instants[(k + 1) % instants.len()];
            let nx = &s.channels[slots[next_t].unwrap()];
            if nx.select > 7 || nx.device as usize >= devices {
                return Err(unsupported(format!(
                    "branch {}: channel device {} select {} outside the branch's muxes",
                    bp.name, nx.device, nx.select
                )));
            }
            words[t] = (1 << 16) | ((ch as u32) << 8) | (nx.select << 5) | nx.device;
        }
        let (reset_sel, reset_en) = match instants.first() {
            Some(&t) => {
                let c0 = &s.channels[slots[t].unwrap()];
                (c0.select, 1u64 << c0.device)
            }
            None => (0, 0),
        };
        branches.push(BranchRom {
            words,
            addr_bits: aw,
            sclk_div: spi.sclk_div,
            sclk_half: spi.sclk_half,
            setup_cycles: spi.setup_cycles,
            read_cycles: spi.read_cycles,
            reset_sel,
            reset_en,
            devices,
            en_offset,
        });
        en_offset += devices;
    }
    Ok(Plan {
        slot_cycles: g.slot_cycles,
        frame_slots: g.frame_slots,
        channel_bits: s.channel_bits(),
        branches,
    })
}
