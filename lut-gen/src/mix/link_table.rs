//! The `[link]` table.

use toml::Spanned;

use super::raw::*;
use super::words::*;
use super::*;

impl Cx<'_> {
    /// `[link]`: the kind, and for a UART a baud the clock can divide to
    /// within [`MAX_BAUD_ERROR_PCT`].
    pub(super) fn link(&self, l: &Spanned<RawLink>, clock_hz: u64) -> Result<LinkSpec, MixError> {
        let r = l.get_ref();
        let kind = match r.kind.get_ref().as_str() {
            "uart" => LinkKind::Uart,
            "axis" => return self.axis_link(l),
            other => {
                return Err(self.at(
                    r.kind.span(),
                    "link.kind",
                    format!("unknown link kind `{other}` (known: \"uart\", \"axis\")"),
                ))
            }
        };
        for (v, k) in [
            (r.tlast.as_ref().map(|x| x.span()), "link.tlast"),
            (
                r.ready_within.as_ref().map(|x| x.span()),
                "link.ready_within",
            ),
        ] {
            if let Some(sp) = v {
                return Err(self.at(
                    sp,
                    k,
                    "only an AXI4-Stream link (kind = \"axis\") has this key",
                ));
            }
        }
        let baud_raw = r
            .baud
            .as_ref()
            .ok_or_else(|| self.at(l.span(), "link.baud", "missing: a UART link needs `baud`"))?;
        let baud = self.positive(baud_raw, "link.baud")?;
        let div = link::UartFormat::divider(clock_hz, baud);
        let real = link::UartFormat::real_baud(clock_hz, div);
        if div < MIN_BAUD_DIVIDER {
            return Err(self.at(
                baud_raw.span(),
                "link.baud",
                format!(
                    "{baud} baud from a {clock_hz} Hz clock is {div} cycle(s) per bit; the link needs at least {MIN_BAUD_DIVIDER} (at most {} baud)",
                    clock_hz / MIN_BAUD_DIVIDER as u64
                ),
            ));
        }
        let err = (real - baud as f64).abs() / baud as f64 * 100.0;
        if err > MAX_BAUD_ERROR_PCT {
            return Err(self.at(
                baud_raw.span(),
                "link.baud",
                format!(
                    "the nearest divider of the {clock_hz} Hz clock ({div}) gives {real:.0} baud, {err:.2} % off {baud}; a receiver tolerates about {MAX_BAUD_ERROR_PCT} %"
                ),
            ));
        }
        let parity = match &r.parity {
            None => link::Parity::None,
            Some(p) => link::Parity::parse(p.get_ref()).ok_or_else(|| {
                self.at(
                    p.span(),
                    "link.parity",
                    format!(
                        "unknown parity `{}` (\"none\", \"even\" or \"odd\")",
                        p.get_ref()
                    ),
                )
            })?,
        };
        let stop_bits = match &r.stop_bits {
            None => 1,
            Some(s) => match *s.get_ref() {
                1 | 2 => *s.get_ref() as u8,
                v => {
                    return Err(self.at(
                        s.span(),
                        "link.stop_bits",
                        format!("{v} stop bits: 1 or 2"),
                    ))
                }
            },
        };
        Ok(LinkSpec {
            kind,
            tlast: link::Tlast::Slice,
            ready_within: 1,
            baud,
            parity,
            stop_bits,
            line: line_col(self.text, baud_raw.span().start).0,
            column: line_col(self.text, baud_raw.span().start).1,
        })
    }

    /// `[link]` with `kind = "axis"`: `tlast` (`"slice"` or `"frame"`) and
    /// `ready_within` (cycles, default 1: an always-ready slave); the UART's
    /// keys are refused.
    pub(super) fn axis_link(&self, l: &Spanned<RawLink>) -> Result<LinkSpec, MixError> {
        let r = l.get_ref();
        for (v, k) in [
            (r.baud.as_ref().map(|x| x.span()), "link.baud"),
            (r.parity.as_ref().map(|x| x.span()), "link.parity"),
            (r.stop_bits.as_ref().map(|x| x.span()), "link.stop_bits"),
        ] {
            if let Some(sp) = v {
                return Err(self.at(
                    sp,
                    k,
                    "an AXI4-Stream link has no baud, parity or stop bits",
                ));
            }
        }
        let tlast = match &r.tlast {
            None => link::Tlast::Slice,
            Some(t) => link::Tlast::parse(t.get_ref()).ok_or_else(|| {
                self.at(
                    t.span(),
                    "link.tlast",
                    format!("unknown tlast `{}` (\"slice\" or \"frame\")", t.get_ref()),
                )
            })?,
        };
        let ready_within = match &r.ready_within {
            None => 1,
            Some(v) => {
                let n = self.positive(v, "link.ready_within")?;
                u32::try_from(n).map_err(|_| {
                    self.at(
                        v.span(),
                        "link.ready_within",
                        format!("{n} cycles is too many"),
                    )
                })?
            }
        };
        let key = line_col(
            self.text,
            r.ready_within.as_ref().map_or(l.span(), |v| v.span()).start,
        );
        Ok(LinkSpec {
            kind: LinkKind::Axis,
            tlast,
            ready_within,
            baud: 0,
            parity: link::Parity::None,
            stop_bits: 0,
            line: key.0,
            column: key.1,
        })
    }
}
