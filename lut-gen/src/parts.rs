//! Part models as data: the datasheet numbers the scheduler and the gateware
//! depend on, and the cycle-level SPI timing derived from them.
//!
//! Sources: `shared/notes/datasheets.md` (AD7940, TMUX1108).  Numbers marked
//! "(check)" there stay parameters here rather than constants in logic.

use serde::Serialize;

/// An SPI SAR ADC whose sampling instant is its CS falling edge.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AdcPart {
    pub name: &'static str,
    pub bits: u32,
    /// Leading zeros before the MSB in the 16-bit serial word.
    pub leading_zeros: u32,
    pub sclk_per_conversion: u32,
    pub sclk_min_hz: u64,
    pub sclk_max_hz: u64,
    /// SCLK mark/space limit: each phase at least this percentage of the period.
    pub duty_min_pct: u32,
    pub max_sps: u64,
    /// t2, CS falling to first SCLK falling edge.
    pub cs_setup_ns: u64,
    /// t_quiet, end of a read to the next CS falling edge.
    pub quiet_ns: u64,
    /// t4, data access after an SCLK falling edge (3 V worst case).
    pub data_access_ns: u64,
    /// t7, data hold after an SCLK falling edge.
    pub data_hold_ns: u64,
}

impl AdcPart {
    pub const AD7940: AdcPart = AdcPart {
        name: "ad7940",
        bits: 14,
        leading_zeros: 2,
        sclk_per_conversion: 16,
        sclk_min_hz: 250_000,
        sclk_max_hz: 2_500_000,
        duty_min_pct: 40,
        max_sps: 100_000,
        cs_setup_ns: 10,
        quiet_ns: 50,
        data_access_ns: 120,
        data_hold_ns: 10,
    };

    pub fn by_name(name: &str) -> Option<AdcPart> {
        match name.to_ascii_lowercase().as_str() {
            "ad7940" => Some(Self::AD7940),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["ad7940"]
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

    pub fn by_name(name: &str) -> Option<MuxPart> {
        match name.to_ascii_lowercase().as_str() {
            "tmux1108" => Some(Self::TMUX1108),
            _ => None,
        }
    }

    pub fn known() -> Vec<&'static str> {
        vec!["tmux1108"]
    }
}

/// Cycle-level timing of one conversion on one branch, in system clock cycles.
///
/// With the sampling instant (CS falling) in cycle `t`:
/// - `cs_n` is low in cycles `t .. t + read_cycles`;
/// - SCLK idles high; falling edge `i` (1..=16) starts cycle
///   `t + setup_cycles + (i-1) * sclk_div`, rising edge `i` starts
///   `sclk_half` cycles later;
/// - the master captures MISO at the clock edge that raises SCLK `i`
///   (bit `i` of the serial word, 1..=15; bit 0 is the first leading zero);
/// - the next CS falling edge is at least `quiet_cycles` after CS rises.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpiTiming {
    /// System clocks per SCLK period; always even, so the duty is exactly 50 %.
    pub sclk_div: u64,
    pub sclk_half: u64,
    pub sclk_hz: f64,
    pub setup_cycles: u64,
    pub quiet_cycles: u64,
    /// Cycles CS stays low: setup plus 16 SCLK periods.
    pub read_cycles: u64,
    /// Shortest distance between two CS falling edges of this branch.
    pub min_period_cycles: u64,
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
    pub fn derive(adc: &AdcPart, clock_hz: u64, sclk_hz: u64) -> Result<SpiTiming, TimingError> {
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
        let setup_cycles = ns_to_cycles(adc.cs_setup_ns, clock_hz).max(1);
        let quiet_cycles = ns_to_cycles(adc.quiet_ns, clock_hz).max(1);
        let read_cycles = setup_cycles + adc.sclk_per_conversion as u64 * div;
        let throughput_cycles = clock_hz.div_ceil(adc.max_sps);
        Ok(SpiTiming {
            sclk_div: div,
            sclk_half: half,
            sclk_hz: actual,
            setup_cycles,
            quiet_cycles,
            read_cycles,
            min_period_cycles: (read_cycles + quiet_cycles).max(throughput_cycles),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ad7940_at_48mhz() {
        let t = SpiTiming::derive(&AdcPart::AD7940, 48_000_000, 2_500_000).unwrap();
        assert_eq!(t.sclk_div, 20); // 2.4 MHz: 19.2 rounded up to even
        assert_eq!(t.setup_cycles, 1);
        assert_eq!(t.quiet_cycles, 3); // 50 ns = 2.4 cycles
        assert_eq!(t.read_cycles, 321);
        assert_eq!(t.min_period_cycles, 480); // the 100 kSPS limit dominates
    }

    #[test]
    fn slow_clock_is_rejected() {
        assert!(SpiTiming::derive(&AdcPart::AD7940, 400_000, 250_000).is_err());
    }
}
