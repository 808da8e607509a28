//! The `[[branch]]` tables.

use std::collections::BTreeMap;

use super::check::{SupplyHint, Timing};
use super::raw::*;
use super::*;
use crate::parts::{AdcPart, MuxPart};

impl Cx<'_> {
    /// Every `[[branch]]`, names unique.
    pub(super) fn branches(
        &self,
        raw: &RawMix,
        parts: &[AdcPart],
        t: &Timing,
    ) -> Result<Vec<Branch>, MixError> {
        let mut known_parts: Vec<String> = AdcPart::known().iter().map(|s| s.to_string()).collect();
        known_parts.extend(parts.iter().map(|p| p.name.clone()));
        let mut branches = Vec::new();
        let mut branch_names: BTreeMap<String, usize> = BTreeMap::new();
        for (i, b) in raw.branch.iter().enumerate() {
            let b = b.get_ref();
            let f = |k: &str| format!("branch[{i}].{k}");
            let bname = b.name.get_ref().clone();
            if bname.trim().is_empty() {
                return Err(self.at(b.name.span(), f("name"), "must not be empty"));
            }
            if branch_names.insert(bname.clone(), i).is_some() {
                return Err(self.at(
                    b.name.span(),
                    f("name"),
                    format!("duplicate branch name `{bname}`"),
                ));
            }
            branches.push(self.branch(i, b, bname, parts, &known_parts, t)?);
        }
        Ok(branches)
    }

    /// One `[[branch]]` past its name: ADC, chain, mux, SCLK, settling.
    pub(super) fn branch(
        &self,
        i: usize,
        b: &RawBranch,
        name: String,
        parts: &[AdcPart],
        known_parts: &[String],
        t: &Timing,
    ) -> Result<Branch, MixError> {
        let f = |k: &str| format!("branch[{i}].{k}");
        let wanted = b.adc.get_ref().to_ascii_lowercase();
        let adc = AdcPart::by_name(&wanted)
            .or_else(|| parts.iter().find(|p| p.name == wanted).cloned())
            .ok_or_else(|| {
                self.at(
                    b.adc.span(),
                    f("adc"),
                    format!(
                        "unknown ADC `{}` (known: {})",
                        b.adc.get_ref(),
                        known_parts.join(", ")
                    ),
                )
            })?;
        let vdd_mv = self.branch_vdd(i, b, &adc)?;
        let adc = adc.at_supply(vdd_mv);
        let chain = self.branch_chain(i, b, &adc)?;
        let mux = self.branch_mux(i, b, &adc)?;
        let sclk_hz = self.branch_sclk(i, b, &name, &adc, vdd_mv)?;
        if t.clock_hz < 2 * adc.sclk_min_hz {
            return Err(self.at(
                t.clock_span.clone(),
                "clock.hz",
                format!(
                    "{} Hz is too slow to generate the {} minimum SCLK",
                    t.clock_hz, adc.name
                ),
            ));
        }
        self.check_late_sampler(i, b, &adc, &mux)?;
        let mux_devices = self.branch_mux_devices(i, b, &mux)?;
        let (mux, mux_devices, fronted) = match &b.front_mux {
            Some(fm) => (
                self.branch_front(i, b, &adc, &mux, fm)?,
                self.front_devices(i, b)?,
                true,
            ),
            None if b.front_mux_devices.is_some() => {
                return Err(self.at(
                    b.front_mux_devices.as_ref().unwrap().span(),
                    f("front_mux_devices"),
                    "counts the devices of a front mux: name it with front_mux as well",
                ))
            }
            None => (mux, mux_devices, false),
        };
        let settle_ns = match &b.settle_ns {
            None => 0,
            Some(s) if *s.get_ref() < 0 => {
                return Err(self.at(s.span(), f("settle_ns"), "must not be negative"));
            }
            Some(s) => *s.get_ref() as u64,
        };
        Ok(Branch {
            name,
            adc,
            sclk_hz,
            sclk_explicit: b.sclk_hz.is_some(),
            mux,
            mux_devices,
            fronted,
            settle_ns,
            chain,
            vdd_mv,
        })
    }

    /// `branch.vdd`: the converter's supply in volts, within the part's
    /// range; only for a part with a supply table (every built-in one).
    pub(super) fn branch_vdd(
        &self,
        i: usize,
        b: &RawBranch,
        adc: &AdcPart,
    ) -> Result<Option<u32>, MixError> {
        let Some(v) = &b.vdd else { return Ok(None) };
        let f = format!("branch[{i}].vdd");
        let volts = match v.get_ref() {
            toml::Value::Integer(n) => *n as f64,
            toml::Value::Float(x) if x.is_finite() => *x,
            other => {
                return Err(self.at(
                    v.span(),
                    f,
                    format!("got `{other}`, expected the supply in volts, e.g. vdd = 5.0"),
                ))
            }
        };
        let Some((lo, hi)) = adc.vdd_range_mv() else {
            return Err(self.at(
                v.span(),
                f,
                format!(
                    "`{}` is declared with one set of figures, not per supply: leave vdd out",
                    adc.name
                ),
            ));
        };
        let mv = (volts * 1000.0).round();
        if mv < lo as f64 || mv > hi as f64 {
            return Err(self.at(
                v.span(),
                f,
                format!(
                    "{volts} V is outside the {} supply range {}..={} V",
                    adc.name,
                    crate::parts::volts(lo),
                    crate::parts::volts(hi)
                ),
            ));
        }
        Ok(Some(mv as u32))
    }

    /// `branch.chain`: how many parts, within the part's limit.
    pub(super) fn branch_chain(
        &self,
        i: usize,
        b: &RawBranch,
        adc: &AdcPart,
    ) -> Result<u32, MixError> {
        let Some(c) = &b.chain else { return Ok(1) };
        let v = self.positive(c, &format!("branch[{i}].chain"))?;
        if v > adc.chain_max as u64 {
            return Err(self.at(
                c.span(),
                format!("branch[{i}].chain"),
                format!(
                    "{v} parts in a chain: `{}` allows at most {}",
                    adc.name, adc.chain_max
                ),
            ));
        }
        Ok(v as u32)
    }

    /// `branch.sclk_hz`: the part's maximum unless given, and within its
    /// range at its supply (`adc` is the part at `vdd_mv`).  Above the
    /// maximum at the lowest supply (no `vdd`) but within a higher supply's,
    /// the error names the supply and leaves a [`SupplyHint`] for `parse`
    /// to try.
    pub(super) fn branch_sclk(
        &self,
        i: usize,
        b: &RawBranch,
        branch: &str,
        adc: &AdcPart,
        vdd_mv: Option<u32>,
    ) -> Result<u64, MixError> {
        let Some(s) = &b.sclk_hz else {
            return Ok(adc.sclk_max_hz);
        };
        let v = self.positive(s, &format!("branch[{i}].sclk_hz"))?;
        if v > adc.sclk_max_hz && adc.vdd_range_mv().is_some() {
            let at = vdd_mv
                .or(adc.supply_figure(None).map(|f| f.from_mv))
                .unwrap_or(0);
            let higher = adc
                .supplies
                .iter()
                .find(|f| f.sclk_max_hz >= v && f.from_mv > at);
            let mut m = format!(
                "{} SCLK {} exceeds its {} at {} V",
                adc.name.to_ascii_uppercase(),
                hz_words(v),
                hz_words(adc.sclk_max_hz),
                crate::parts::volts(at)
            );
            if vdd_mv.is_none() {
                m.push_str(" (its lowest supply: the figure without `vdd`)");
            }
            if let Some(h) = higher {
                m.push_str(&format!(
                    "; its datasheet allows {} from {} V",
                    hz_words(h.sclk_max_hz),
                    crate::parts::volts(h.from_mv)
                ));
                if vdd_mv.is_none() {
                    self.hint.borrow_mut().replace(SupplyHint {
                        branch: branch.to_string(),
                        vdd_mv: h.from_mv,
                        part: adc.name.clone(),
                    });
                }
            }
            return Err(self.at(s.span(), format!("branch[{i}].sclk_hz"), m));
        }
        if v > adc.sclk_max_hz || v < adc.sclk_min_hz {
            return Err(self.at(
                s.span(),
                format!("branch[{i}].sclk_hz"),
                format!(
                    "{v} Hz is outside the {} SCLK range {}..={} Hz",
                    adc.name, adc.sclk_min_hz, adc.sclk_max_hz
                ),
            ));
        }
        Ok(v)
    }

    /// A part that samples inside its transaction (after its CS edge)
    /// cannot have an external mux: its pins move on one cycle after CS
    /// falls (docs/timing.md), before the part holds its input.
    pub(super) fn check_late_sampler(
        &self,
        i: usize,
        b: &RawBranch,
        adc: &AdcPart,
        mux: &MuxPart,
    ) -> Result<(), MixError> {
        if adc.sample == crate::parts::SampleAt::Start || mux.is_internal() || *mux == MuxPart::NONE
        {
            return Ok(());
        }
        Err(self.at(
            b.mux.span(),
            format!("branch[{i}].mux"),
            format!(
                "`{}` holds its input {}, after an external mux's pins have moved on to the next conversion (one cycle after CS falls): use mux = \"none\"",
                adc.name,
                adc.sample.words(adc.start)
            ),
        ))
    }

    /// `branch.mux`: an external part, or `internal` (the converter's own,
    /// chosen by its command word).  A part with a command word takes
    /// `internal`; an external mux in front of it is `front_mux`.
    pub(super) fn branch_mux(
        &self,
        i: usize,
        b: &RawBranch,
        adc: &AdcPart,
    ) -> Result<MuxPart, MixError> {
        let f = format!("branch[{i}].mux");
        let wanted = b.mux.get_ref().to_ascii_lowercase();
        match (&adc.command, wanted.as_str()) {
            (Some(c), "internal") => Ok(MuxPart::internal(c.channels())),
            (None, "internal") => Err(self.at(
                b.mux.span(),
                f,
                format!(
                    "`{}` has no multiplexer of its own (no command word): use an external mux or \"none\"",
                    adc.name
                ),
            )),
            (Some(_), _) if MuxPart::by_name(&wanted).is_some() => Err(self.at(
                b.mux.span(),
                f,
                format!(
                    "`{}` selects its input with its command word: write mux = \"internal\" (and front_mux = \"{}\" for an external mux wired in front of its inputs)",
                    adc.name, wanted
                ),
            )),
            _ => MuxPart::by_name(&wanted).ok_or_else(|| {
                self.at(
                    b.mux.span(),
                    f,
                    format!(
                        "unknown mux `{}` (known: {})",
                        b.mux.get_ref(),
                        MuxPart::known().join(", ")
                    ),
                )
            }),
        }
    }

    /// `branch.front_mux`: an external mux wired in front of the
    /// converter's own, where the part permits it.  The front mux's pins
    /// follow an external-mux branch's rule (docs/timing.md): they address
    /// a conversion's input from the cycle after the branch's previous
    /// instant through the instant itself, and move on one cycle after it.
    /// A part whose word applies to the conversion that carries it
    /// (`ahead` 0: the MCP3208, section 5.0, holds its input at the falling
    /// SCLK after the 6th rising one since CS fell, inside the transaction)
    /// would sample the next conversion's front input: refused, as is any
    /// part that samples after its start edge ([`crate::parts::SampleAt`]).  A part that
    /// samples at its instant (CNV rising, or a CS part whose word applies
    /// to a later conversion, as the AD7689 and the ADS7953) has its front
    /// input settled there, whatever its word selects.
    pub(super) fn branch_front(
        &self,
        i: usize,
        b: &RawBranch,
        adc: &AdcPart,
        mux: &MuxPart,
        fm: &toml::Spanned<String>,
    ) -> Result<MuxPart, MixError> {
        let f = format!("branch[{i}].front_mux");
        if !mux.is_internal() {
            return Err(self.at(
                fm.span(),
                f,
                format!(
                    "names a mux in front of the converter's own: it needs mux = \"internal\" (this branch has mux = \"{}\")",
                    b.mux.get_ref()
                ),
            ));
        }
        let wanted = fm.get_ref().to_ascii_lowercase();
        let front = MuxPart::by_name(&wanted)
            .filter(|m| *m != MuxPart::NONE)
            .ok_or_else(|| {
                let known: Vec<&str> = MuxPart::known()
                    .into_iter()
                    .filter(|k| !matches!(*k, "none" | "internal"))
                    .collect();
                self.at(
                    fm.span(),
                    f.clone(),
                    format!(
                        "unknown front mux `{}` (known: {})",
                        fm.get_ref(),
                        known.join(", ")
                    ),
                )
            })?;
        let ahead = adc.command.as_ref().map_or(0, |c| c.ahead);
        if ahead == 0 || adc.sample != crate::parts::SampleAt::Start {
            return Err(self.at(
                fm.span(),
                f,
                format!(
                    "`{}` samples its input inside the transaction that carries its word (the word applies to the same conversion), after the front mux's pins have moved on to the next conversion (one cycle after CS falls): a front mux needs a part that samples at its CS or CNV edge and applies its word to a later conversion (command_ahead >= 1, as the ad7689)",
                    adc.name
                ),
            ));
        }
        Ok(front)
    }

    /// `branch.front_mux_devices`: 1 to 32 (1 unless given).
    pub(super) fn front_devices(&self, i: usize, b: &RawBranch) -> Result<u32, MixError> {
        let Some(m) = &b.front_mux_devices else {
            return Ok(1);
        };
        let f = format!("branch[{i}].front_mux_devices");
        let v = self.positive(m, &f)?;
        if v > 32 {
            return Err(self.at(m.span(), f, "at most 32 front mux devices per branch"));
        }
        Ok(v as u32)
    }

    /// `branch.mux_devices`: 1 to 32, and only with an external mux.
    pub(super) fn branch_mux_devices(
        &self,
        i: usize,
        b: &RawBranch,
        mux: &MuxPart,
    ) -> Result<u32, MixError> {
        let f = |k: &str| format!("branch[{i}].{k}");
        match &b.mux_devices {
            None => Ok(1),
            Some(m) if *mux == MuxPart::NONE => Err(self.at(
                m.span(),
                f("mux_devices"),
                "a branch with mux = \"none\" has no mux devices",
            )),
            Some(m) if mux.is_internal() => Err(self.at(
                m.span(),
                f("mux_devices"),
                "the converter's own multiplexer (mux = \"internal\") has no devices to count",
            )),
            Some(m) => {
                let v = self.positive(m, &f("mux_devices"))?;
                if v > 32 {
                    return Err(self.at(
                        m.span(),
                        f("mux_devices"),
                        "at most 32 mux devices per branch",
                    ));
                }
                Ok(v as u32)
            }
        }
    }
}

/// Hz as a datasheet writes them: `2 MHz`, `2.5 MHz`, `250 kHz`.
pub(crate) fn hz_words(hz: u64) -> String {
    let (v, unit) = if hz >= 1_000_000 {
        (hz as f64 / 1e6, "MHz")
    } else if hz >= 1_000 {
        (hz as f64 / 1e3, "kHz")
    } else {
        (hz as f64, "Hz")
    };
    let t = format!("{v:.3}");
    format!("{} {unit}", t.trim_end_matches('0').trim_end_matches('.'))
}
