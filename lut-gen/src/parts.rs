//! Part models as data: the datasheet numbers the scheduler, the gateware
//! generator, the ADC model and the checker all read, and the cycle-level SPI
//! timing derived from them.
//!
//! Sources: the AD7940, AD7685 and TMUX1108 datasheets.  Numbers not
//! confirmed there stay parameters here rather than constants in logic.
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

/// A SAR ADC with a serial read-out, as data.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AdcPart {
    pub name: String,
    /// Data bits per word, MSB first.
    pub bits: u32,
    pub start: Start,
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
}

impl AdcPart {
    pub fn ad7940() -> AdcPart {
        AdcPart {
            name: "ad7940".into(),
            bits: 14,
            start: Start::Cs,
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
        }
    }

    /// Serial clocks per word: leading bits, data bits, trailing bits.
    pub fn word_sclks(&self) -> u32 {
        self.leading_bits + self.bits + self.trailing_bits
    }

    pub fn by_name(name: &str) -> Option<AdcPart> {
        match name.to_ascii_lowercase().as_str() {
            "ad7940" => Some(Self::ad7940()),
            "ad7685" => Some(Self::ad7685()),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["ad7940", "ad7685"]
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

    pub fn by_name(name: &str) -> Option<MuxPart> {
        match name.to_ascii_lowercase().as_str() {
            "tmux1108" => Some(Self::TMUX1108),
            "none" => Some(Self::NONE),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["tmux1108", "none"]
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
    /// Cycles the conversion pin stays active: setup plus every SCLK period.
    pub read_cycles: u64,
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
        Ok(SpiTiming {
            sclk_div: div,
            sclk_half: half,
            sclk_hz: actual,
            setup_cycles,
            quiet_cycles,
            read_cycles,
            min_period_cycles: (read_cycles + quiet_cycles).max(throughput_cycles),
            style: adc.start,
            words: chain,
            word_sclks: adc.word_sclks(),
            bits: adc.bits,
            leading_bits: adc.leading_bits,
            conv_cycles,
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ad7940_at_48mhz() {
        let t = SpiTiming::derive(&AdcPart::ad7940(), 48_000_000, 2_500_000, 1).unwrap();
        assert_eq!(t.sclk_div, 20); // 2.4 MHz: 19.2 rounded up to even
        assert_eq!(t.setup_cycles, 1);
        assert_eq!(t.quiet_cycles, 3); // 50 ns = 2.4 cycles
        assert_eq!(t.read_cycles, 321);
        assert_eq!(t.min_period_cycles, 480); // the 100 kSPS limit dominates
        assert_eq!(t.captures().count(), 15);
    }

    #[test]
    fn ad7685_chain_of_four_at_48mhz() {
        let p = AdcPart::ad7685();
        let t = SpiTiming::derive(&p, 48_000_000, p.sclk_max_hz, 4).unwrap();
        assert_eq!(t.sclk_div, 4); // 12 MHz
        assert_eq!(t.conv_cycles, 154); // 3.2 us = 153.6 cycles
        assert_eq!(t.setup_cycles, 155);
        assert_eq!(t.read_cycles, 155 + 64 * 4);
        assert_eq!(t.captures().count(), 64);
        assert_eq!(t.min_period_cycles, 412); // read + quiet: longer than 200 kSPS
                                              // so the chain gives 4 x 48 MHz / 412 samples/s, not 4 x 200 kSPS
        assert_eq!(t.max_samples_hz(48_000_000).floor(), 466_019.0);
    }

    #[test]
    fn slow_clock_is_rejected() {
        assert!(SpiTiming::derive(&AdcPart::ad7940(), 400_000, 250_000, 1).is_err());
    }
}
