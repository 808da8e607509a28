//! The read of a part read with CNV low, seen as a held read.
//!
//! The checker's rules work in the CS view: a conversion is a window in
//! which the conversion pin is active, from the conversion start to the end
//! of the read.  A part read with CNV low (the AD7689) has no such pin: CNV
//! is high for the conversion and low for the read, and low again between
//! conversions.  [`LowRead::view`] gives such a lane the window it would
//! have had: active while CNV is high and after it falls until the read's
//! last SCK falling edge (or the next CNV rising).  On the real pins it
//! checks what only this read has: SCK idle while CNV is high, CNV high for
//! the whole conversion, and the MSB's access time after CNV falls before
//! the first SCK edge.

use serde_json::json;

use lut_gen::{Layout, Pins, Signal};

use crate::model::Invariants;
use crate::model::Rule;
use crate::model::Violation;

/// One lane's read, in the real pins.
#[derive(Debug, Clone, Default)]
struct Lane {
    /// The window is open (converting, or reading after CNV fell).
    open: bool,
    /// The window in the last view given (`None` before the first: the
    /// pin's own level stands for it).
    active: Option<bool>,
    /// SCK falling edges since CNV fell.
    falls: u32,
    rose_at: u64,
    fell_at: Option<u64>,
    /// Limits, in cycles: SCK periods per conversion, the conversion time,
    /// CNV low to the first SCK edge.
    sclks: u32,
    conv_min: u64,
    en_min: u64,
}

/// The lanes of a mix read with CNV low (none: [`LowRead::view`] is the
/// identity).
#[derive(Debug, Clone, Default)]
pub(crate) struct LowRead {
    mask: u16,
    lanes: Vec<Lane>,
}

impl LowRead {
    pub(crate) fn new(s: &lut_gen::Schedule) -> LowRead {
        let clock = s.mix.clock_hz;
        let mut mask = 0;
        let mut lanes = Vec::new();
        for (b, br) in s.mix.branches.iter().enumerate() {
            let low =
                br.adc.start == lut_gen::Start::Cnv && br.adc.read == lut_gen::CnvRead::CnvLow;
            mask |= (low as u16) << b;
            lanes.push(Lane {
                sclks: br.adc.word_sclks() * br.chain,
                conv_min: lut_gen::ns_to_cycles(br.adc.conversion_ns, clock),
                en_min: lut_gen::ns_to_cycles(br.adc.setup_ns, clock).max(1),
                ..Lane::default()
            });
        }
        LowRead { mask, lanes }
    }

    /// The lanes' windows as [`LowRead::view`] last gave them, into `view`
    /// (the CS view of the pins it was given).
    pub(crate) fn last_view(&self, view: &mut Pins) {
        for (b, l) in self.lanes.iter().enumerate() {
            if let Some(a) = l.active.filter(|_| self.mask >> b & 1 == 1) {
                let bit = 1u16 << b;
                view.cs_n = (view.cs_n & !bit) | if a { 0 } else { bit };
            }
        }
    }

    /// `view` (the CS view of `p`, CNV lanes inverted) with each lane read
    /// with CNV low given its window; `prev` is the cycle before's real pins.
    /// Call it once per cycle in which a pin changed, in order.
    pub(crate) fn view(
        &mut self,
        c: u64,
        prev: &Pins,
        p: &Pins,
        view: &mut Pins,
        layout: &Layout,
        inv: &mut Invariants,
    ) {
        if self.mask == 0 {
            return;
        }
        for b in 0..self.lanes.len() {
            let bit = 1u16 << b;
            if self.mask & bit == 0 {
                continue;
            }
            let cnv = p.cs_n & bit != 0;
            let was = prev.cs_n & bit != 0;
            let edge = (p.sclk ^ prev.sclk) & bit != 0;
            let fall = edge && p.sclk & bit == 0;
            let l = &mut self.lanes[b];
            if cnv && !was {
                l.rose_at = c;
                l.fell_at = None;
            }
            if !cnv && was {
                l.fell_at = Some(c);
                if c - l.rose_at < l.conv_min {
                    inv.record(
                        Violation::new(Rule::CsSetup, c)
                            .signal(Signal::CsN(b).name(layout))
                            .expected(json!(l.conv_min))
                            .actual(json!(c - l.rose_at))
                            .detail(format!(
                                "CNV high for {} cycles, the conversion takes {} (t_CONV): the read would begin before it ends",
                                c - l.rose_at,
                                l.conv_min
                            )),
                    );
                }
            }
            if edge {
                Self::edge_rules(l, b, c, cnv, layout, inv);
            }
            if cnv {
                l.open = true;
                l.falls = 0;
            } else if l.open && fall {
                l.falls += 1;
                l.open = l.falls < l.sclks;
            }
            let active = cnv || l.open;
            l.active = Some(active);
            view.cs_n = (view.cs_n & !bit) | if active { 0 } else { bit };
        }
    }

    /// An SCK edge: never while CNV is high, and the first not before the
    /// MSB is out (t_EN after CNV fell).
    fn edge_rules(
        l: &mut Lane,
        b: usize,
        c: u64,
        cnv: bool,
        layout: &Layout,
        inv: &mut Invariants,
    ) {
        if cnv {
            inv.record(
                Violation::new(Rule::SclkIdle, c)
                    .signal(Signal::Sclk(b).name(layout))
                    .detail("SCK toggles while CNV is high: the part drives SDO and takes DIN only while CNV is low"),
            );
            return;
        }
        if let Some(f) = l.fell_at.take() {
            if c - f < l.en_min {
                inv.record(
                    Violation::new(Rule::CsSetup, c)
                        .signal(Signal::Sclk(b).name(layout))
                        .expected(json!(l.en_min))
                        .actual(json!(c - f))
                        .detail(format!(
                            "the first SCK edge {} cycles after CNV fell, the MSB needs {} (t_EN)",
                            c - f,
                            l.en_min
                        )),
                );
            }
        }
    }
}
