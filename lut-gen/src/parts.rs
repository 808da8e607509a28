//! Part models as data: the datasheet numbers the scheduler, the gateware
//! generator, the ADC model and the checker all read, and the cycle-level SPI
//! timing derived from them.
//!
//! Sources: the AD7940, AD7685, MCP3208, AD7689 and TMUX1108 datasheets.
//! Numbers not confirmed there stay parameters here rather than constants in
//! logic.  A part may take a command word on its data input ([`Command`]).
//! A mix may declare its own parts (`[[adc_part]]`, `crate::mix`); they use
//! the same two conversion styles ([`Start`]).

use serde::Serialize;

/// What starts a conversion (and is therefore the sampling instant).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Start {
    /// CS falling starts the conversion; the word is read in the same CS-low
    /// window (AD7940): SCLK idles high, `leading_bits` come before the MSB.
    Cs,
    /// CNV rising starts the conversion; after `conversion_ns` the word(s)
    /// are clocked out, MSB first (AD7685 in chain mode, no busy indicator:
    /// CNV stays high through conversion and readback, SCK idles low).
    Cnv,
}

impl Start {
    /// The mix file's spelling.
    pub fn key(self) -> &'static str {
        match self {
            Start::Cs => "cs",
            Start::Cnv => "cnv",
        }
    }

    /// Level of the conversion pin while a conversion runs (CS is active
    /// low, CNV active high).
    pub fn active_level(self) -> bool {
        matches!(self, Start::Cnv)
    }

    /// Level of the conversion pin between conversions.
    pub fn idle_level(self) -> bool {
        !self.active_level()
    }

    /// Idle level of the serial clock (CPOL).
    pub fn sclk_idle(self) -> bool {
        matches!(self, Start::Cs)
    }
}

/// How a CNV part is read once its conversion ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CnvRead {
    /// CNV stays high through the read-back (the AD7685's chain mode; CS
    /// parts hold CS low likewise).
    #[default]
    CnvHigh,
    /// CNV returns low when the conversion ends and the word is read while
    /// it is low: the part drives SDO and latches DIN only then (the AD7689's
    /// read after conversion, the AD768x "CS mode, 3-wire").
    CnvLow,
}

impl CnvRead {
    /// The mix file's spelling.
    pub fn key(self) -> &'static str {
        match self {
            CnvRead::CnvHigh => "cnv-high",
            CnvRead::CnvLow => "cnv-low",
        }
    }

    fn is_cnv_high(&self) -> bool {
        *self == CnvRead::CnvHigh
    }
}

/// Where in its transaction a part holds its input (its sampling instant),
/// as its datasheet says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleAt {
    /// At the edge that starts the conversion: CS falling (AD7940, a "cs"
    /// part) or CNV rising (AD7685, AD7689, a "cnv" part).
    #[default]
    Start,
    /// At the falling SCLK edge after rising SCLK edge `n`, counted from CS
    /// falling: the end of the part's sample window inside its
    /// transaction (MCP3208: `n` = 6, DS21298E section 5.0).
    SclkFall(u32),
}

impl SampleAt {
    fn is_start(&self) -> bool {
        *self == SampleAt::Start
    }

    /// The instant in words, as the audit and errors say it.
    pub fn words(self, start: Start) -> String {
        match (self, start) {
            (SampleAt::Start, Start::Cs) => "at its CS fall".into(),
            (SampleAt::Start, Start::Cnv) => "at its CNV rise".into(),
            (SampleAt::SclkFall(n), _) => {
                format!(
                    "at the falling SCLK edge after the {}{} rising one since CS fell",
                    n,
                    ordinal(n)
                )
            }
        }
    }
}

fn ordinal(n: u32) -> &'static str {
    match (n % 10, n % 100) {
        (1, x) if x != 11 => "st",
        (2, x) if x != 12 => "nd",
        (3, x) if x != 13 => "rd",
        _ => "th",
    }
}

/// A part's datasheet figures at one supply: they hold from `from_mv` up to
/// the next figure's supply (or the part's `vdd_max_mv`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Supply {
    /// The lowest VDD, in millivolts, these figures hold at.
    pub from_mv: u32,
    pub sclk_max_hz: u64,
    pub max_sps: u64,
    /// CNV parts: t_CONV max at this supply; 0 for CS parts.
    pub conversion_ns: u64,
}

/// Millivolts as volts the way a user writes them: `5.0`, `2.7`, `4.5`.
pub fn volts(mv: u32) -> String {
    let s = format!("{:.2}", mv as f64 / 1000.0);
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    }
}

/// A SAR ADC with a serial read-out, as data.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AdcPart {
    pub name: String,
    /// Data bits per word, MSB first.
    pub bits: u32,
    pub start: Start,
    /// CNV parts: whether CNV is high or low while the word is read.
    #[serde(skip_serializing_if = "CnvRead::is_cnv_high")]
    pub read: CnvRead,
    /// Serial clocks before the MSB (the AD7940's two leading zeros).
    pub leading_bits: u32,
    /// Serial clocks after the LSB.
    pub trailing_bits: u32,
    pub sclk_min_hz: u64,
    pub sclk_max_hz: u64,
    /// SCLK mark/space limit: each phase at least this percentage of the period.
    pub duty_min_pct: u32,
    pub max_sps: u64,
    /// CS falling (or, for CNV parts, the end of the conversion) to the first
    /// SCLK edge.
    pub setup_ns: u64,
    /// End of a read to the next conversion start.
    pub quiet_ns: u64,
    /// CNV parts: CNV rising to data available (t_CONV max); 0 for CS parts.
    pub conversion_ns: u64,
    /// Data access after an SCLK edge that shifts the next bit out.
    pub data_access_ns: u64,
    /// Data hold after that edge.
    pub data_hold_ns: u64,
    /// How many parts may share one port in a daisy chain.
    pub chain_max: u32,
    /// The command word the part takes on DIN (its own multiplexer's
    /// channel); `None`: the part only listens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<Command>,
    /// Where in its transaction the part holds its input.
    #[serde(skip_serializing_if = "SampleAt::is_start")]
    pub sample: SampleAt,
    /// The datasheet's figures by supply, lowest supply first (`sclk_max_hz`,
    /// `max_sps` and `conversion_ns` above are the first's until
    /// [`AdcPart::at_supply`] picks another); empty for a declared part (one
    /// set of figures, no supply range).
    #[serde(skip)]
    pub supplies: Vec<Supply>,
    /// The highest VDD the part takes, in millivolts (0: no supply range).
    #[serde(skip)]
    pub vdd_max_mv: u32,
}

/// One bit of a command word, as its template spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum CmdBit {
    Zero,
    One,
    /// Bit `k` of the channel number (0: its LSB).
    Channel(u8),
}

/// A command word sent on DIN (the FPGA's `adc_mosi`) while a conversion is
/// read: one bit per SCLK period from the first, first bit first, held for
/// the whole period (the part latches DIN on the rising SCLK edge in the
/// middle of it); bits past the word are 0.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
pub struct Command {
    pub bits: Vec<CmdBit>,
    /// Which conversion the word selects, counted from the one whose read
    /// carries it: 0 the same (MCP3208: the channel is in the transaction),
    /// 2 the conversion after next (AD7689's CFG).
    pub ahead: u32,
}

impl Command {
    /// A template: `0`, `1` and `C` (a channel bit, MSB first), `_` as a
    /// separator.  At least one `C`, at most 32 bits; 3 `C`s give 8 channels.
    pub fn parse(template: &str, ahead: u32) -> Result<Command, String> {
        let chars: Vec<char> = template.chars().filter(|&c| c != '_').collect();
        let width = chars.iter().filter(|&&c| c == 'C' || c == 'c').count();
        if width == 0 {
            return Err(format!(
                "`{template}` has no channel bit: write the channel's bits as C (MSB first)"
            ));
        }
        if width > 4 || chars.len() > 32 {
            return Err(format!(
                "`{template}`: at most 32 bits and 4 channel bits (16 channels)"
            ));
        }
        let mut k = width;
        let mut bits = Vec::new();
        for c in chars {
            bits.push(match c {
                '0' => CmdBit::Zero,
                '1' => CmdBit::One,
                'C' | 'c' => {
                    k -= 1;
                    CmdBit::Channel(k as u8)
                }
                other => {
                    return Err(format!(
                        "`{template}`: `{other}` is not a bit (0, 1, C for a channel bit, _)"
                    ))
                }
            });
        }
        Ok(Command { bits, ahead })
    }

    /// The template spelling ([`Command::parse`] of it gives `self`).
    pub fn template(&self) -> String {
        self.bits
            .iter()
            .map(|b| match b {
                CmdBit::Zero => '0',
                CmdBit::One => '1',
                CmdBit::Channel(_) => 'C',
            })
            .collect()
    }

    /// Channels the word can select: 2 to the number of channel bits.
    pub fn channels(&self) -> u32 {
        let w = self
            .bits
            .iter()
            .filter(|b| matches!(b, CmdBit::Channel(_)))
            .count();
        1 << w
    }

    /// The word that selects `channel`, first bit first.
    pub fn word(&self, channel: u32) -> Vec<bool> {
        self.bits
            .iter()
            .map(|b| match *b {
                CmdBit::Zero => false,
                CmdBit::One => true,
                CmdBit::Channel(k) => channel >> k & 1 == 1,
            })
            .collect()
    }

    /// The channel a received word selects (the inverse of [`Command::word`]
    /// on the channel bits), or `None` when a fixed bit differs or the word
    /// is short: the part would not convert a channel the mix asked for.
    pub fn channel_of(&self, word: &[bool]) -> Option<u32> {
        let mut ch = 0;
        for (i, b) in self.bits.iter().enumerate() {
            let v = *word.get(i)?;
            match *b {
                CmdBit::Zero if v => return None,
                CmdBit::One if !v => return None,
                CmdBit::Channel(k) => ch |= (v as u32) << k,
                _ => {}
            }
        }
        Some(ch)
    }
}

impl AdcPart {
    pub fn ad7940() -> AdcPart {
        AdcPart {
            name: "ad7940".into(),
            bits: 14,
            start: Start::Cs,
            read: CnvRead::CnvHigh,
            leading_bits: 2,
            trailing_bits: 0,
            sclk_min_hz: 250_000,
            sclk_max_hz: 2_500_000,
            duty_min_pct: 40,
            max_sps: 100_000,
            setup_ns: 10,
            quiet_ns: 50,
            conversion_ns: 0,
            data_access_ns: 120,
            data_hold_ns: 10,
            chain_max: 1,
            command: None,
            sample: SampleAt::Start,
            // Rev. A, Table 2: one column for VDD 2.5 V to 5.5 V
            supplies: vec![Supply {
                from_mv: 2_500,
                sclk_max_hz: 2_500_000,
                max_sps: 100_000,
                conversion_ns: 0,
            }],
            vdd_max_mv: 5_500,
        }
    }

    /// AD7685, VDD 2.3-4.5 V column (the conservative one): t_CONV 3.2 us
    /// max, t_CYC 5 us (200 kSPS), SCK period >= 40 ns in chain mode at
    /// VIO 2.3 V (12.5 MHz used as the limit here, with margin for the
    /// 35 ns t_DSDO), up to eight parts chained per the datasheet example.
    pub fn ad7685() -> AdcPart {
        AdcPart {
            name: "ad7685".into(),
            bits: 16,
            start: Start::Cnv,
            read: CnvRead::CnvHigh,
            leading_bits: 0,
            trailing_bits: 0,
            sclk_min_hz: 1,
            sclk_max_hz: 12_500_000,
            duty_min_pct: 40,
            max_sps: 200_000,
            setup_ns: 10,
            quiet_ns: 10,
            conversion_ns: 3_200,
            data_access_ns: 35,
            data_hold_ns: 5,
            chain_max: 8,
            command: None,
            sample: SampleAt::Start,
            // Rev. D, Tables 4 and 5: t_CONV 2.2 us, t_CYC 4 us from 4.5 V
            supplies: vec![
                Supply {
                    from_mv: 2_300,
                    sclk_max_hz: 12_500_000,
                    max_sps: 200_000,
                    conversion_ns: 3_200,
                },
                Supply {
                    from_mv: 4_500,
                    sclk_max_hz: 12_500_000,
                    max_sps: 250_000,
                    conversion_ns: 2_200,
                },
            ],
            vdd_max_mv: 5_500,
        }
    }

    /// MCP3208 (Microchip DS21298E), the VDD = 2.7 V column of Table 1-1
    /// (the conservative one, its lowest supply; `supplies` holds the 5 V
    /// column, [`AdcPart::at_supply`]): f_CLK 1 MHz max, 50 ksps; t_SUCS (CS fall to
    /// the first rising clock) 100 ns, t_CSH (CS disable) 500 ns, t_DO (clock
    /// fall to data valid) 200 ns; below 10 kHz the sample capacitor droops
    /// (section 6.2).  Section 5.0 and Figure 6-1 give the word: the start
    /// bit and SGL/DIFF, then D2 D1 D0 on the first five rising clocks; one
    /// more clock completes the sample (the input is held at the falling
    /// edge after rising edge 6, [`SampleAt::SclkFall`]), the null bit follows and B11..B0 are
    /// read on rising edges 8..19: eight serial bits before the MSB, one
    /// clock after the LSB.  SPI mode 1,1: SCLK idles high, the same style as
    /// the AD7940.
    pub fn mcp3208() -> AdcPart {
        AdcPart {
            name: "mcp3208".into(),
            bits: 12,
            start: Start::Cs,
            read: CnvRead::CnvHigh,
            leading_bits: 8,
            trailing_bits: 0,
            sclk_min_hz: 10_000,
            sclk_max_hz: 1_000_000,
            duty_min_pct: 40,
            max_sps: 50_000,
            setup_ns: 100,
            quiet_ns: 500,
            conversion_ns: 0,
            data_access_ns: 200,
            data_hold_ns: 0,
            chain_max: 1,
            command: Some(Command::parse("11CCC", 0).expect("a valid template")),
            // Section 5.0: the sample window opens on the 4th rising clock
            // after the start bit and ends on the falling edge of the 5th
            // clock after it; the start bit is latched on rising edge 1, so
            // the input is held at the falling edge after rising edge 6.
            sample: SampleAt::SclkFall(6),
            // Table 1-1: f_CLK 1 MHz / 50 ksps at VDD 2.7 V, 2 MHz / 100 ksps at 5 V
            supplies: vec![
                Supply {
                    from_mv: 2_700,
                    sclk_max_hz: 1_000_000,
                    max_sps: 50_000,
                    conversion_ns: 0,
                },
                Supply {
                    from_mv: 5_000,
                    sclk_max_hz: 2_000_000,
                    max_sps: 100_000,
                    conversion_ns: 0,
                },
            ],
            vdd_max_mv: 5_500,
        }
    }

    /// AD7689 (Analog Devices AD7682/AD7689 Rev. D), Table 4 (timing):
    /// t_CONV 2.2 us max, t_CYC 4 us (250 kSPS), t_DSDO 25 ns at VIO 1.8 V
    /// or more (the slowest column); SCK limited to 12.5 MHz here as for the
    /// AD7685.  Read after conversion (Figure 41, "General Timing Without a
    /// Busy Indicator"): CNV high for t_CONV, then low; SDO and DIN are
    /// enabled only while CNV is low (t_EN, CNV low to the MSB, 25 ns at the
    /// slowest VIO, is the setup; t_CLSCK, CNV low to SCK, 10 ns, is within it).  "Digital Interface": the 14-bit CFG is written on the first
    /// 14 SCK rising edges of the read-back and applies to the conversion
    /// after next (from power-up the first results are undefined: "two
    /// dummy conversions are required").  CFG, MSB first: CFG = 1 (write),
    /// INCC = 111 (unipolar, INx referenced to GND), INx = the channel, BW
    /// = 1 (full), REF = 001 (internal 4.096 V), SEQ = 00 (no sequencer),
    /// RB = 1 (no read-back of the CFG).
    pub fn ad7689() -> AdcPart {
        AdcPart {
            name: "ad7689".into(),
            bits: 16,
            start: Start::Cnv,
            read: CnvRead::CnvLow,
            leading_bits: 0,
            trailing_bits: 0,
            sclk_min_hz: 1,
            sclk_max_hz: 12_500_000,
            duty_min_pct: 40,
            max_sps: 250_000,
            setup_ns: 25,
            quiet_ns: 10,
            conversion_ns: 2_200,
            data_access_ns: 25,
            data_hold_ns: 4,
            chain_max: 1,
            command: Some(Command::parse("1111_CCC_1_001_00_1", 2).expect("a valid template")),
            sample: SampleAt::Start,
            // Rev. D, Table 4: one column for VDD 2.3 V to 5.5 V
            supplies: vec![Supply {
                from_mv: 2_300,
                sclk_max_hz: 12_500_000,
                max_sps: 250_000,
                conversion_ns: 2_200,
            }],
            vdd_max_mv: 5_500,
        }
    }

    /// The part at supply `vdd_mv` (`None`: its lowest supply): its SCLK,
    /// throughput and conversion figures from the datasheet's column for
    /// the highest supply at or below it.  A part without a supply table
    /// is itself.
    pub fn at_supply(&self, vdd_mv: Option<u32>) -> AdcPart {
        let mut p = self.clone();
        if let Some(f) = self.supply_figure(vdd_mv) {
            p.sclk_max_hz = f.sclk_max_hz;
            p.max_sps = f.max_sps;
            p.conversion_ns = f.conversion_ns;
        }
        p
    }

    /// The datasheet column that holds at `vdd_mv` (`None`: the lowest).
    pub fn supply_figure(&self, vdd_mv: Option<u32>) -> Option<Supply> {
        let v = vdd_mv.unwrap_or(0);
        self.supplies
            .iter()
            .rev()
            .find(|f| f.from_mv <= v)
            .or(self.supplies.first())
            .copied()
    }

    /// The supply range the part takes, in millivolts (`None`: a declared
    /// part without one).
    pub fn vdd_range_mv(&self) -> Option<(u32, u32)> {
        let lo = self.supplies.first()?.from_mv;
        Some((lo, self.vdd_max_mv))
    }

    /// Serial clocks per word: leading bits, data bits, trailing bits.
    pub fn word_sclks(&self) -> u32 {
        self.leading_bits + self.bits + self.trailing_bits
    }

    pub fn by_name(name: &str) -> Option<AdcPart> {
        match name.to_ascii_lowercase().as_str() {
            "ad7940" => Some(Self::ad7940()),
            "ad7685" => Some(Self::ad7685()),
            "mcp3208" => Some(Self::mcp3208()),
            "ad7689" => Some(Self::ad7689()),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["ad7940", "ad7685", "mcp3208", "ad7689"]
    }
}

/// An analog multiplexer: devices share address lines and are chosen by EN.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct MuxPart {
    pub name: &'static str,
    pub inputs: u32,
    pub select_bits: u32,
}

impl MuxPart {
    pub const TMUX1108: MuxPart = MuxPart {
        name: "tmux1108",
        inputs: 8,
        select_bits: 3,
    };

    /// No multiplexer: the converter is wired straight to its sensor (one
    /// input).  The branch has no mux lanes in the pin contract (no
    /// `mux_sel`, no `mux_en` bits: `lut_gen::Layout::muxed`).
    pub const NONE: MuxPart = MuxPart {
        name: "none",
        inputs: 1,
        select_bits: 0,
    };

    /// The converter's own multiplexer (`mux = "internal"`), chosen by its
    /// command word: `channels` inputs, no pins of the FPGA's own (no
    /// `mux_sel`, no `mux_en`).
    pub fn internal(channels: u32) -> MuxPart {
        MuxPart {
            name: "internal",
            inputs: channels,
            select_bits: 0,
        }
    }

    /// Whether this is the converter's own multiplexer.
    pub fn is_internal(&self) -> bool {
        self.name == "internal"
    }

    /// An external part by name (`internal` depends on the converter: see
    /// [`MuxPart::internal`]).
    pub fn by_name(name: &str) -> Option<MuxPart> {
        match name.to_ascii_lowercase().as_str() {
            "tmux1108" => Some(Self::TMUX1108),
            "none" => Some(Self::NONE),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["tmux1108", "none", "internal"]
    }
}

/// Cycle-level timing of one conversion on one branch, in system clock cycles.
///
/// With the sampling instant (CS falling, or CNV rising) in cycle `t`:
/// - the conversion pin is active in cycles `t .. t + read_cycles`;
/// - `setup_cycles` (for CNV parts: the conversion time plus the setup) pass
///   before the first serial clock period; period `i` (1..=`sclks`) starts in
///   cycle `t + setup_cycles + (i-1) * sclk_div`, and its second half
///   `sclk_half` cycles later;
/// - CS parts: SCLK idles high, falls at the start of a period and rises in
///   its middle; the master captures serial bit `i` (bit 0 is the first
///   leading bit, never read) at rising edge `i`, `i = 1..sclks`;
/// - CNV parts: SCK idles low, rises in the middle of a period (rising edge
///   `i`) and falls at its end; the master captures serial bit `i - 1` (bit 0
///   is the MSB of the first word, on SDO when the conversion ends) at rising
///   edge `i`, `i = 1..=sclks`;
/// - the next conversion starts at least `quiet_cycles` after the pin is
///   released.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpiTiming {
    /// System clocks per SCLK period; always even, so the duty is exactly 50 %.
    pub sclk_div: u64,
    pub sclk_half: u64,
    pub sclk_hz: f64,
    pub setup_cycles: u64,
    pub quiet_cycles: u64,
    /// Cycles from the instant to the end of the read: setup plus every
    /// SCLK period.
    pub read_cycles: u64,
    /// Cycles the conversion pin stays active from the instant: the whole
    /// read, or for a part read with CNV low ([`CnvRead::CnvLow`]) the
    /// conversion alone.
    #[serde(skip)]
    pub pin_cycles: u64,
    /// Shortest distance between two conversion starts of this branch.
    pub min_period_cycles: u64,
    #[serde(skip)]
    pub style: Start,
    /// Words read per conversion (parts in the chain).
    #[serde(skip)]
    pub words: u32,
    /// Serial clocks per word.
    #[serde(skip)]
    pub word_sclks: u32,
    /// Data bits per word and clocks before the MSB.
    #[serde(skip)]
    pub bits: u32,
    #[serde(skip)]
    pub leading_bits: u32,
    /// CNV parts: cycles from CNV rising to data available.
    #[serde(skip)]
    pub conv_cycles: u64,
    /// Cycles from the transaction's start (CS falling, CNV rising) to the
    /// part's sampling instant ([`SampleAt`]): 0 at the start edge; for
    /// [`SampleAt::SclkFall`]`(n)` the cycle SCLK falls after rising edge
    /// `n`, the start of serial period `n + 1`.
    #[serde(skip)]
    pub sample_cycles: u64,
    /// Cycles from the slot tick to the transaction's start: 0 unless a
    /// sync group links the branch to a part that holds its input later
    /// in its transaction, whose instant this one's waits for
    /// ([`SpiTiming::with_holdoff`]). CS/CNV stay idle meanwhile.
    #[serde(skip_serializing_if = "is_zero")]
    pub holdoff_cycles: u64,
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

/// Why a branch's part cannot be driven from this clock.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TimingError(pub String);

/// Cycles covering `ns` nanoseconds at `clock_hz`, rounded up.
pub fn ns_to_cycles(ns: u64, clock_hz: u64) -> u64 {
    (ns as u128 * clock_hz as u128).div_ceil(1_000_000_000) as u64
}

pub fn cycles_to_ns(cycles: u64, clock_hz: u64) -> f64 {
    cycles as f64 * 1e9 / clock_hz as f64
}

impl SpiTiming {
    /// Timing of one conversion of `chain` parts of `adc` sharing the port.
    pub fn derive(
        adc: &AdcPart,
        clock_hz: u64,
        sclk_hz: u64,
        chain: u32,
    ) -> Result<SpiTiming, TimingError> {
        let mut div = clock_hz.div_ceil(sclk_hz).max(2);
        if div % 2 == 1 {
            div += 1;
        }
        let actual = clock_hz as f64 / div as f64;
        if actual < adc.sclk_min_hz as f64 {
            return Err(TimingError(format!(
                "no even clock divider of {clock_hz} Hz gives an SCLK within {}..={} Hz",
                adc.sclk_min_hz, adc.sclk_max_hz
            )));
        }
        let half = div / 2;
        if cycles_to_ns(half, clock_hz) < adc.data_access_ns as f64 {
            return Err(TimingError(format!(
                "SCLK low phase {:.0} ns is shorter than the {} ns data access time",
                cycles_to_ns(half, clock_hz),
                adc.data_access_ns
            )));
        }
        let conv_cycles = match adc.start {
            Start::Cs => 0,
            Start::Cnv => ns_to_cycles(adc.conversion_ns, clock_hz),
        };
        let setup_cycles = conv_cycles + ns_to_cycles(adc.setup_ns, clock_hz).max(1);
        let quiet_cycles = ns_to_cycles(adc.quiet_ns, clock_hz).max(1);
        let sclks = adc.word_sclks() as u64 * chain as u64;
        let read_cycles = setup_cycles + sclks * div;
        let throughput_cycles = clock_hz.div_ceil(adc.max_sps);
        let sample_cycles = match adc.sample {
            SampleAt::Start => 0,
            SampleAt::SclkFall(n) => setup_cycles + n as u64 * div,
        };
        let pin_cycles = match (adc.start, adc.read) {
            (Start::Cnv, CnvRead::CnvLow) => conv_cycles,
            _ => read_cycles,
        };
        Ok(SpiTiming {
            sclk_div: div,
            sclk_half: half,
            sclk_hz: actual,
            setup_cycles,
            quiet_cycles,
            read_cycles,
            pin_cycles,
            min_period_cycles: (read_cycles + quiet_cycles).max(throughput_cycles),
            style: adc.start,
            words: chain,
            word_sclks: adc.word_sclks(),
            bits: adc.bits,
            leading_bits: adc.leading_bits,
            conv_cycles,
            sample_cycles,
            holdoff_cycles: 0,
        })
    }

    /// This timing with its transaction started `holdoff` cycles after the
    /// slot tick.
    pub fn with_holdoff(self, holdoff: u64) -> SpiTiming {
        SpiTiming {
            holdoff_cycles: holdoff,
            ..self
        }
    }

    /// Cycles from the slot tick to the instant the part holds its input:
    /// the hold-off plus the part's own [`SpiTiming::sample_cycles`].
    pub fn tick_to_sample(&self) -> u64 {
        self.holdoff_cycles + self.sample_cycles
    }

    /// Cycles from the slot tick to the end of the read (the pin released).
    pub fn tick_to_complete(&self) -> u64 {
        self.holdoff_cycles + self.read_cycles
    }

    /// Conversions per second the part allows on this port: one every
    /// `min_period_cycles` (the conversion, every word of the chain read at
    /// the SCLK used, the quiet time, and the datasheet's throughput limit).
    pub fn max_conversions_hz(&self, clock_hz: u64) -> f64 {
        clock_hz as f64 / self.min_period_cycles.max(1) as f64
    }

    /// Samples per second the port allows: [`Self::max_conversions_hz`]
    /// times the words of the chain.  The one figure of a branch's converter
    /// maximum: the audit's branch table, its parts table, its total and the
    /// utilizations are all this value.
    pub fn max_samples_hz(&self, clock_hz: u64) -> f64 {
        self.max_conversions_hz(clock_hz) * self.words as f64
    }

    /// Serial clock periods per conversion (every word of the chain).
    pub fn sclks(&self) -> u64 {
        self.word_sclks as u64 * self.words as u64
    }

    /// Cycle offsets (from the instant) during which the master's capture
    /// flip-flop samples MISO, with the serial bit index each one reads
    /// (0 = the first bit on the line).  CS parts skip bit 0 (a leading
    /// zero driven before any clock).
    pub fn captures(&self) -> impl Iterator<Item = (u64, u64)> + '_ {
        let first = match self.style {
            Start::Cs => 1,
            Start::Cnv => 0,
        };
        let n = self.sclks();
        let (su, d, h) = (self.setup_cycles, self.sclk_div, self.sclk_half);
        (first..n).map(move |bit| {
            // CS: bit i is read at rising edge i; CNV: bit i at rising edge i + 1.
            let edge = match self.style {
                Start::Cs => bit,
                Start::Cnv => bit + 1,
            };
            (su + (edge - 1) * d + h - 1, bit)
        })
    }

    /// The code of word `w` (0 = the first word out) in a serial stream of
    /// `sclks()` bits, bit 0 first (MSB first).
    pub fn code_of(&self, stream: &[bool], w: usize) -> u16 {
        let base = w * self.word_sclks as usize + self.leading_bits as usize;
        let mut v = 0u32;
        for i in 0..self.bits as usize {
            v = (v << 1) | stream.get(base + i).copied().unwrap_or(false) as u32;
        }
        v as u16
    }

    /// Mask of a code of this part.
    pub fn code_mask(&self) -> u16 {
        ((1u32 << self.bits) - 1) as u16
    }
}
