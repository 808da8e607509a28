//! A declared `[[adc_part]]`, checked like every other field.

use super::raw::*;
use super::*;
use crate::parts::{AdcPart, CnvRead, Command, SampleAt, Start};

impl Cx<'_> {
    /// A `[[adc_part]]` table, checked like every other field.
    pub(super) fn adc_part(&self, i: usize, p: &RawAdcPart) -> Result<AdcPart, MixError> {
        let f = |k: &str| format!("adc_part[{i}].{k}");
        let name = self.adc_part_name(i, p)?;
        let bits = self.positive(&p.bits, &f("bits"))?;
        if bits > 16 {
            return Err(self.at(
                p.bits.span(),
                f("bits"),
                format!("{bits} data bits: the sample stream carries at most 16"),
            ));
        }
        let start = match p.start.get_ref().as_str() {
            "cs" => Start::Cs,
            "cnv" => Start::Cnv,
            other => return Err(self.unknown_start(i, p, other)),
        };
        let leading_bits = self.nonneg(&p.leading_bits, &f("leading_bits"), 0)?;
        let trailing_bits = self.nonneg(&p.trailing_bits, &f("trailing_bits"), 0)?;
        if leading_bits + bits + trailing_bits > 32 {
            return Err(self.at(
                p.bits.span(),
                f("bits"),
                "leading + data + trailing bits exceed 32 serial clocks per word",
            ));
        }
        if start == Start::Cs && leading_bits == 0 {
            return Err(self.at(
                p.start.span(),
                f("leading_bits"),
                "a \"cs\" part drives its first bit at CS falling, before any clock: it needs at least one leading bit (the MSB cannot be the first bit)",
            ));
        }
        let sclk_max_hz = self.positive(&p.sclk_max_hz, &f("sclk_max_hz"))?;
        let sclk_min_hz = self.nonneg(&p.sclk_min_hz, &f("sclk_min_hz"), 1)?.max(1);
        if sclk_min_hz > sclk_max_hz {
            return Err(self.at(
                p.sclk_min_hz
                    .as_ref()
                    .map(|s| s.span())
                    .unwrap_or(p.sclk_max_hz.span()),
                f("sclk_min_hz"),
                format!("{sclk_min_hz} Hz is above sclk_max_hz {sclk_max_hz} Hz"),
            ));
        }
        let duty_min_pct = self.nonneg(&p.duty_min_pct, &f("duty_min_pct"), 40)?;
        if duty_min_pct > 50 {
            return Err(self.at(
                p.duty_min_pct.as_ref().unwrap().span(),
                f("duty_min_pct"),
                format!("{duty_min_pct} %: no clock has both phases above half the period"),
            ));
        }
        let conversion_ns = self.nonneg(&p.conversion_ns, &f("conversion_ns"), 0)?;
        if start == Start::Cs && conversion_ns != 0 {
            return Err(self.at(
                p.conversion_ns.as_ref().unwrap().span(),
                f("conversion_ns"),
                "a \"cs\" part converts while it is read: conversion_ns applies to \"cnv\" parts only",
            ));
        }
        let max_sps = self.positive(&p.max_sps, &f("max_sps"))?;
        let read = self.adc_part_read(i, p, start)?;
        if read == CnvRead::CnvLow && conversion_ns == 0 {
            return Err(self.at(
                p.read.as_ref().unwrap().span(),
                f("conversion_ns"),
                "a part read with CNV low holds CNV high for the conversion: give its conversion_ns (t_CONV max)",
            ));
        }
        let chain_max = self.adc_part_chain(i, p, start)?;
        if read == CnvRead::CnvLow && chain_max > 1 {
            return Err(self.at(
                p.chain_max.as_ref().unwrap().span(),
                f("chain_max"),
                "a chain is read with CNV high (chain mode): a part read with CNV low is not chained here",
            ));
        }
        Ok(AdcPart {
            name,
            bits: bits as u32,
            start,
            read,
            leading_bits: leading_bits as u32,
            trailing_bits: trailing_bits as u32,
            sclk_min_hz,
            sclk_max_hz,
            duty_min_pct: duty_min_pct as u32,
            max_sps,
            setup_ns: self.nonneg(&p.setup_ns, &f("setup_ns"), 10)?,
            quiet_ns: self.nonneg(&p.quiet_ns, &f("quiet_ns"), 0)?,
            conversion_ns,
            data_access_ns: self.nonneg(&p.data_access_ns, &f("data_access_ns"), 0)?,
            data_hold_ns: 0,
            chain_max: chain_max as u32,
            command: self.adc_part_command(i, p, chain_max, leading_bits + bits + trailing_bits)?,
            sample: self.adc_part_sample(i, p, start, leading_bits + bits + trailing_bits)?,
            supplies: Vec::new(),
            vdd_max_mv: 0,
        })
    }

    /// `adc_part.sample_after_rising`: the rising SCLK edge (counted from CS
    /// falling) whose falling edge after it is the sampling instant; a "cs"
    /// part's only, inside its word.  Absent: the CS or CNV edge.
    pub(super) fn adc_part_sample(
        &self,
        i: usize,
        p: &RawAdcPart,
        start: Start,
        word_sclks: u64,
    ) -> Result<SampleAt, MixError> {
        let Some(n) = &p.sample_after_rising else {
            return Ok(SampleAt::Start);
        };
        let f = format!("adc_part[{i}].sample_after_rising");
        let v = self.positive(n, &f)?;
        if start == Start::Cnv {
            return Err(self.at(
                n.span(),
                f,
                "a \"cnv\" part samples at CNV rising: sample_after_rising applies to \"cs\" parts only",
            ));
        }
        if v >= word_sclks {
            return Err(self.at(
                n.span(),
                f,
                format!("rising edge {v}: the word has {word_sclks} serial clocks, and the instant is the falling edge after it, inside the word (at most {})", word_sclks - 1),
            ));
        }
        Ok(SampleAt::SclkFall(v as u32))
    }

    /// `adc_part.command` and `command_ahead`: a template of the word on
    /// DIN, and which conversion it selects (0: the one it is sent in).
    pub(super) fn adc_part_command(
        &self,
        i: usize,
        p: &RawAdcPart,
        chain_max: u64,
        word_sclks: u64,
    ) -> Result<Option<Command>, MixError> {
        let f = |k: &str| format!("adc_part[{i}].{k}");
        let Some(t) = &p.command else {
            if let Some(a) = &p.command_ahead {
                return Err(self.at(
                    a.span(),
                    f("command_ahead"),
                    "applies to a command word: declare `command` as well",
                ));
            }
            return Ok(None);
        };
        let ahead = self.nonneg(&p.command_ahead, &f("command_ahead"), 0)?;
        if ahead > 4 {
            return Err(self.at(
                p.command_ahead.as_ref().unwrap().span(),
                f("command_ahead"),
                format!("{ahead} conversions ahead: at most 4"),
            ));
        }
        if chain_max > 1 {
            return Err(self.at(
                t.span(),
                f("command"),
                "a part with a command word is not daisy-chained here: leave chain_max at 1",
            ));
        }
        let c = Command::parse(t.get_ref(), ahead as u32)
            .map_err(|m| self.at(t.span(), f("command"), m))?;
        let lead = self.nonneg(&p.leading_bits, &f("leading_bits"), 0)?;
        if c.bits.len() as u64 > word_sclks {
            return Err(self.at(
                t.span(),
                f("command"),
                format!(
                    "{} bits: longer than the part's {word_sclks} serial clocks per word",
                    c.bits.len()
                ),
            ));
        }
        if ahead == 0 && c.bits.len() as u64 > lead {
            return Err(self.at(
                t.span(),
                f("command"),
                format!(
                    "{} bits select the conversion they are sent in: the part must have at least as many leading_bits ({lead}) before its first data bit",
                    c.bits.len()
                ),
            ));
        }
        Ok(Some(c))
    }

    /// `adc_part.name`: lower case, not blank, not a built-in part's.
    pub(super) fn adc_part_name(&self, i: usize, p: &RawAdcPart) -> Result<String, MixError> {
        let name = p.name.get_ref().trim().to_ascii_lowercase();
        if name.is_empty() {
            return Err(self.at(
                p.name.span(),
                format!("adc_part[{i}].name"),
                "must not be empty",
            ));
        }
        if AdcPart::by_name(&name).is_some() {
            return Err(self.at(
                p.name.span(),
                format!("adc_part[{i}].name"),
                format!("`{name}` is a built-in part; give the declared part its own name"),
            ));
        }
        Ok(name)
    }

    /// `adc_part.read`: how a "cnv" part is read (CNV high unless given).
    pub(super) fn adc_part_read(
        &self,
        i: usize,
        p: &RawAdcPart,
        start: Start,
    ) -> Result<CnvRead, MixError> {
        let Some(r) = &p.read else {
            return Ok(CnvRead::CnvHigh);
        };
        let key = format!("adc_part[{i}].read");
        let read = match r.get_ref().as_str() {
            "cnv-high" => CnvRead::CnvHigh,
            "cnv-low" => CnvRead::CnvLow,
            other => {
                return Err(self.at(
                    r.span(),
                    key,
                    format!("unknown read `{other}` (\"cnv-high\": CNV stays high through the read, as in the AD7685's chain mode; \"cnv-low\": CNV returns low when the conversion ends and the word is read while it is low, as the AD7689 is)"),
                ))
            }
        };
        if start == Start::Cs {
            return Err(self.at(
                r.span(),
                key,
                "a \"cs\" part is read while CS is low: `read` applies to \"cnv\" parts only",
            ));
        }
        Ok(read)
    }

    pub(super) fn unknown_start(&self, i: usize, p: &RawAdcPart, other: &str) -> MixError {
        self.at(
            p.start.span(),
            format!("adc_part[{i}].start"),
            format!("unknown start `{other}` (\"cs\": CS falling starts the conversion, \"cnv\": CNV rising)"),
        )
    }

    /// `adc_part.chain_max`: 1 unless given; only "cnv" parts chain.
    pub(super) fn adc_part_chain(
        &self,
        i: usize,
        p: &RawAdcPart,
        start: Start,
    ) -> Result<u64, MixError> {
        let Some(c) = &p.chain_max else { return Ok(1) };
        let v = self.positive(c, &format!("adc_part[{i}].chain_max"))?;
        if v > 1 && start == Start::Cs {
            return Err(self.at(
                c.span(),
                format!("adc_part[{i}].chain_max"),
                "chains are read in one CNV-high window: only \"cnv\" parts chain here",
            ));
        }
        Ok(v)
    }
}
